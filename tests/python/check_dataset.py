"""Reads a dataset written by `motorfactory generate` back with independent readers (numpy,
Open3D, tomllib) and checks it against its manifest, sample JSONs and labels.

Usage: python3 tests/python/check_dataset.py DATASET_DIR N
(the dataset needs output.formats = ["ply", "pcd", "npy", "npz"])
"""
import json
import os
import sys
import tomllib

import numpy as np
import open3d as o3d

from checks import check, report


def main(root, n):
    config = tomllib.load(open(f"{root}/config.toml", "rb"))
    check("config samples", config["samples"] == n, config["samples"])
    labels = json.load(open(f"{root}/labels.json"))
    classes = labels["classes"]
    check("labels ids in order", [c["id"] for c in classes] == list(range(len(classes))))
    rows = [json.loads(line) for line in open(f"{root}/manifest.jsonl")]
    check("manifest rows", [r["index"] for r in rows] == list(range(n)), len(rows))
    listed = set()
    seen = np.zeros(len(classes), np.int64)
    for r in rows:
        doc = json.load(open(f"{root}/{r['json']}"))
        listed.add(r["json"])
        listed.update(r["files"])
        tag = r["json"]
        check(f"{tag} split folder", r["json"].startswith(doc["split"] + "/"))
        check(f"{tag} json matches row", doc["index"] == r["index"] and doc["level"] == r["level"])
        files = {os.path.splitext(f)[1] if not f.endswith("_ascii.pcd") else "ascii": f for f in r["files"]}
        count = r["points"][0]
        table = np.load(f"{root}/{files['.npy']}")
        check(f"{tag} npy N x 7 float32", table.shape == (count, 7) and table.dtype == np.float32, table.shape)
        label = table[:, 6].astype(np.int64)
        check(f"{tag} npy labels in scheme", label.min() >= 0 and label.max() < len(classes))
        seen += np.bincount(label, minlength=len(classes))
        check(f"{tag} class counts", list(np.bincount(label, minlength=len(classes))) == r["class_counts"])
        npz = np.load(f"{root}/{files['.npz']}")
        check(f"{tag} npz equals npy", np.array_equal(npz["xyz"], table[:, :3]) and np.array_equal(npz["label"], label)
              and np.allclose(npz["rgb"] / 255.0, table[:, 3:6], atol=1e-6))
        # Open3D's tensor reader keeps the PLY's labels: the class is the npy's label
        tensor = o3d.t.io.read_point_cloud(f"{root}/{files['.ply']}").point
        check(f"{tag} open3d tensor ply labels", "class" in tensor and "instance" in tensor, list(tensor))
        if "class" in tensor and "instance" in tensor:
            check(f"{tag} open3d tensor ply class", np.array_equal(tensor["class"].numpy().ravel(), label))
            check(f"{tag} open3d tensor ply instance", np.array_equal(tensor["instance"].numpy().ravel(), npz["instance"]))
        for ext in [".ply", ".pcd"]:
            pc = o3d.io.read_point_cloud(f"{root}/{files[ext]}")
            pts = np.asarray(pc.points)
            check(f"{tag} open3d {ext}", pts.shape == (count, 3) and np.allclose(pts, table[:, :3], atol=1e-6), pts.shape)
            check(f"{tag} open3d {ext} colours", np.allclose(np.asarray(pc.colors), table[:, 3:6], atol=1e-6))
        # every point inside the crop box (world), up to the jitter after cropping
        pose = np.array(doc["views"][0]["camera_to_world"], np.float64)
        world = table[:, :3].astype(np.float64) @ pose[:3, :3].T + pose[:3, 3]
        slack = np.linalg.norm(doc["jitter"]) + 1e-5
        lo, hi = np.array(doc["crop"]["min"]), np.array(doc["crop"]["max"])
        check(f"{tag} inside crop", np.all(world >= lo - slack) and np.all(world <= hi + slack))
        check(f"{tag} plausible size", count > 5000, count)
    on_disk = set()
    for split in ["train", "validation"]:
        on_disk.update(f"{split}/{f}" for f in os.listdir(f"{root}/{split}"))
    check("manifest lists every file", on_disk == listed, on_disk ^ listed)
    check("every class appears", np.all(seen > 0), seen)
    return report("dataset readers")


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], int(sys.argv[2])))
