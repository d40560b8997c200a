"""Reads a dataset's COCO instance files with pycocotools: every annotation's mask (annToMask)
is its instance's pixels in instances.png, its box and area are the mask's, ids are unique, and
COCOeval of the ground truth against itself gives an AP of 1 for boxes and masks.

    python3 check_coco.py DATASET_DIR [polygons|rle]
"""

import contextlib
import io
import json
import re
import sys
from pathlib import Path

import numpy as np
from PIL import Image
from pycocotools import mask as mask_utils
from pycocotools.coco import COCO
from pycocotools.cocoeval import COCOeval


def check(path, kind):
    with contextlib.redirect_stdout(io.StringIO()):
        coco = COCO(str(path))
    root = path.parent.parent
    anns = coco.loadAnns(coco.getAnnIds())
    assert anns, f"{path}: no annotations"
    assert len({a["id"] for a in anns}) == len(anns), "annotation ids repeat"
    assert min(c["id"] for c in coco.loadCats(coco.getCatIds())) == 1, "categories are 1-based"
    for image in coco.loadImgs(coco.getImgIds()):
        instances = np.array(Image.open(root / re.sub(r"rgb\.(png|jpg)$", "instances.png", image["file_name"])))
        rgb = Image.open(root / image["file_name"])
        assert rgb.size == (image["width"], image["height"]), (rgb.size, image)
        for ann in coco.loadAnns(coco.getAnnIds(imgIds=image["id"])):
            want = instances == ann["instance"]
            got = coco.annToMask(ann).astype(bool)
            wrong = int((got != want).sum())
            assert wrong == 0, f"{image['file_name']} instance {ann['instance']}: {wrong} pixels differ"
            seg = ann["segmentation"]
            assert isinstance(seg, dict) == (kind == "rle"), type(seg)
            assert ann["area"] == want.sum(), (ann["area"], want.sum())
            assert 0 < ann["visible_fraction"] <= 1, ann["visible_fraction"]
            box = mask_utils.toBbox(coco.annToRLE(ann)).tolist()
            assert ann["bbox"] == box, (ann["bbox"], box)
            ys, xs = np.nonzero(want)
            assert ann["bbox"] == [xs.min(), ys.min(), xs.max() - xs.min() + 1, ys.max() - ys.min() + 1]
    results = [dict(a, score=1.0) for a in anns]
    for kind_of_iou in ("bbox", "segm"):
        with contextlib.redirect_stdout(io.StringIO()):
            evaluation = COCOeval(coco, coco.loadRes(results), kind_of_iou)
            evaluation.evaluate()
            evaluation.accumulate()
            evaluation.summarize()
        ap = evaluation.stats[0]
        assert abs(ap - 1.0) < 1e-9, f"{path} {kind_of_iou}: AP {ap}"
    return len(anns), len(coco.getImgIds())


def main():
    root = Path(sys.argv[1])
    kind = sys.argv[2] if len(sys.argv) > 2 else "polygons"
    files = sorted((root / "annotations").glob("instances_*.json"))
    assert files, "no annotations/instances_*.json"
    for path in files:
        n, images = check(path, kind)
        print(f"{path.name}: {images} images, {n} annotations: masks, boxes and areas exact, AP 1.0")


if __name__ == "__main__":
    main()
