"""Reads a `hall` dataset back with independent readers (laspy for the LAS, numpy for the NPZ
and Blensor's .numpy table, Open3D for the PLY) and checks each pass against its manifest row,
its JSON and the hall's geometry.

Usage: python3 tests/python/check_hall.py DATASET_DIR SAMPLES
(made with lidar.formats = ["las", "npz", "blensor-numpy", "ply"], points in the head's frame)
"""
import json
import sys
from pathlib import Path

import laspy
import numpy as np
import open3d as o3d

from checks import check, report


def world(doc, points, time):
    """Points of the head's frame at each firing, in the world: the pass's start pose moved
    by the robot's velocity (it does not turn) for the firing time."""
    pose = np.array(doc["head_to_world"])
    velocity = np.array(doc["motion"]["velocity"])
    return points @ pose[:3, :3].T + pose[:3, 3] + time[:, None] * velocity


def main(root, samples):
    root = Path(root)
    rows = [json.loads(line) for line in (root / "manifest.jsonl").read_text().splitlines()]
    check("a manifest row a pass", [r["index"] for r in rows] == list(range(int(samples))))
    starts = {}
    for row in rows:
        doc = json.loads((root / row["json"]).read_text())
        files = {Path(f).suffix: root / f for f in row["files"]}
        check("the four formats' files", sorted(files) == [".las", ".npz", ".numpy", ".ply"], sorted(files))
        n = row["points"][0]
        check("the JSON's returns are the row's points", doc["returns"] == n)
        npz = np.load(files[".npz"])
        las = laspy.read(files[".las"])
        table = np.loadtxt(files[".numpy"], ndmin=2)
        ply = o3d.t.io.read_point_cloud(str(files[".ply"]))
        check("every file holds every return",
              (len(npz["xyz"]), len(las.points), len(table), len(ply.point.positions)) == (n,) * 4,
              (len(npz["xyz"]), len(las.points), len(table), n))
        check("LAS classes are the row's class counts",
              np.bincount(las.classification, minlength=len(row["class_counts"])).tolist() == row["class_counts"])
        check("LAS point source is the instance", np.array_equal(las.point_source_id, npz["instance"]))
        check("LAS user data is the ring", np.array_equal(las.user_data, npz["ring"]))
        check("the table's object id is the instance", np.array_equal(table[:, 11].astype(int), npz["instance"]))
        check("the PLY's points are the measured ones",
              np.allclose(ply.point.positions.numpy(), npz["xyz_noisy"], atol=1e-5))
        instances = {o["instance"] for o in doc["objects"]}
        check("every instance hit is an object of the hall", set(np.unique(npz["instance"]).tolist()) <= instances)
        floor = next(o["instance"] for o in doc["objects"] if o["name"] == "floor")
        on_floor = npz["instance"] == floor
        ideal = world(doc, npz["xyz"], npz["time"])
        check("floor returns lie on the floor in the world (pose, motion and times agree)",
              on_floor.sum() > n / 4 and np.abs(ideal[on_floor, 2]).max() < 1e-3,
              np.abs(ideal[on_floor, 2]).max())
        check("nothing below the floor", ideal[:, 2].min() > -1e-3, ideal[:, 2].min())
        hall, revolution = doc["hall"], doc["revolution"]
        pose = np.array(doc["head_to_world"])
        if hall in starts:
            first, speed = starts[hall]
            period = 1.0 / doc["lidar"]["rotation"]
            step = np.linalg.norm(pose[:3, 3] - first)
            check("the robot drives its speed a revolution", abs(step - speed * period * revolution) < 1e-3,
                  (step, speed * period * revolution))
        elif revolution == 0:
            starts[hall] = (pose[:3, 3], np.linalg.norm(doc["motion"]["velocity"]))
    return report("hall dataset")


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:]))
