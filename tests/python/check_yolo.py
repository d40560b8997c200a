"""Reads a dataset's YOLO folder: every image has its labels, every label line its class in
data.yaml's names and its coordinates within the image, and each line is its part's pixels in
instances.png: a box exactly the mask's, a polygon whose even-odd fill at the pixel centres is
the mask. With Ultralytics installed, its own checks (check_det_dataset, verify_image_label)
pass too.

    python3 check_yolo.py DATASET_DIR detect|segment
"""

import sys
from pathlib import Path

import numpy as np
from PIL import Image


def names(yaml_path):
    out, inside = {}, False
    for line in yaml_path.read_text().splitlines():
        if line.startswith("names:"):
            inside = True
        elif inside and line.startswith("  "):
            k, v = line.strip().split(": ", 1)
            out[int(k)] = v
    return out


def fill(xy, width, height):
    """Even-odd fill of the polygon xy (pixels) at every pixel centre."""
    px, py = np.meshgrid(np.arange(width) + 0.5, np.arange(height) + 0.5)
    inside = np.zeros((height, width), dtype=bool)
    for (x0, y0), (x1, y1) in zip(xy, np.roll(xy, -1, axis=0)):
        if y0 == y1:
            continue
        spans = (y0 > py) != (y1 > py)
        x = x0 + (py - y0) / (y1 - y0) * (x1 - x0)
        inside ^= spans & (px < x)
    return inside


def main():
    root, kind = Path(sys.argv[1]), sys.argv[2]
    yolo = root / "yolo"
    classes = names(yolo / "data.yaml")
    labels = images = 0
    for split in ("train", "val"):
        for image_path in sorted((yolo / "images" / split).glob("*.png")):
            label_path = yolo / "labels" / split / (image_path.stem + ".txt")
            rgb = np.array(Image.open(image_path))
            height, width = rgb.shape[:2]
            # the same image as the sample's own rgb.png, and its instances beside it
            sample = root / ("train" if split == "train" else "validation") / image_path.name.replace(".png", "_rgb.png")
            if sample.exists():
                assert (np.array(Image.open(sample)) == rgb).all(), image_path
            instances = np.array(Image.open(str(sample).replace("_rgb.png", "_instances.png")))
            lines = label_path.read_text().splitlines()
            masks = {}
            for line in lines:
                values = line.split()
                c = int(values[0])
                assert c in classes, (label_path, c)
                v = np.array([float(x) for x in values[1:]])
                assert ((v >= 0) & (v <= 1)).all(), (label_path, line[:80])
                if kind == "detect":
                    assert len(v) == 4
                    cx, cy, w, h = v * [width, height, width, height]
                    box = np.round([cx - w / 2, cy - h / 2, w, h]).astype(int)
                    # the box is exactly one instance's mask's box
                    found = False
                    for i in np.unique(instances):
                        ys, xs = np.nonzero(instances == i)
                        if [xs.min(), ys.min(), xs.max() - xs.min() + 1, ys.max() - ys.min() + 1] == box.tolist():
                            found = True
                            break
                    assert found, (label_path, line)
                else:
                    xy = v.reshape(-1, 2) * [width, height]
                    mask = fill(xy, width, height)
                    ids = np.unique(instances[mask])
                    assert len(ids) == 1, (label_path, ids)
                    assert (mask == (instances == ids[0])).all(), (label_path, int(ids[0]))
                labels += 1
            images += 1
            try:
                from ultralytics.data.utils import verify_image_label
            except ImportError:
                continue
            # (image, labels, prefix, keypoints, classes, keypoints' count and dims, single class)
            _, nf, _, nc, msg = verify_image_label(
                (str(image_path), str(label_path), "", False, len(classes), 0, 0, False)
            )[-5:]
            assert nf == 1 and nc == 0 and not msg, (image_path, msg)
    assert labels > 0, "no labels"
    print(f"yolo {kind}: {images} images, {labels} labels: classes, boxes and masks exact")
    try:
        from ultralytics.data.utils import check_det_dataset
    except ImportError:
        return
    data = check_det_dataset(str(yolo / "data.yaml"))
    assert data["nc"] == len(classes) and data["names"] == classes, data
    print(f"Ultralytics: check_det_dataset and verify_image_label accept {images} images")


if __name__ == "__main__":
    main()
