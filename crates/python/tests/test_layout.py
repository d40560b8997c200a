"""A dataset in the flat layout, read as KIT's AgiProbot segmentation loader reads a folder."""

import json
import os
import subprocess

import numpy as np


def agiprobot_split(data_dir, mode, num_class, test_area="Validation"):
    """The file selection and reading of AgiProbot's ``MotorDataset`` (large_motor_segmentation):
    every file of the folder, sorted, the split by ``test_area`` in its name, each ``np.load``ed
    whole, points its first three columns and labels its seventh."""
    motor_list = sorted(os.listdir(data_dir))
    if mode == "train":
        chosen = [m for m in motor_list if test_area not in m]
    else:
        chosen = [m for m in motor_list if test_area in m]
    counts = np.zeros(num_class)
    points = []
    for name in chosen:
        data = np.load(os.path.join(data_dir, name))
        labels = data[:, 6]
        points.append(data[:, 0:3])
        counts += np.histogram(labels, bins=num_class, range=(0, num_class))[0]
    return chosen, points, counts


def test_the_flat_layout_is_split_by_file_name_as_agiprobot_reads_it(cli, tmp_path):
    out = tmp_path / "flat"
    subprocess.run(
        [str(cli), "generate", "-n", "12", "--quiet", "--out", str(out),
         "--set", "output.layout=flat", "--set", 'output.formats=["npy"]',
         "--set", "output.scheme=wacv6", "--set", "output.units=millimetres",
         "--set", "sensor.sampling=blueSubsample4x4"],
        check=True,
    )
    rows = [json.loads(line) for line in (out / "manifest.jsonl").read_text().splitlines()]
    by_split = {s: sorted(os.path.basename(f) for r in rows if r["split"] == s for f in r["files"])
                for s in ("train", "validation")}
    assert len(by_split["validation"]) >= 2
    classes = len(json.loads((out / "labels.json").read_text())["classes"])
    assert classes == 6
    for mode, split in (("train", "train"), ("validation", "validation")):
        chosen, points, counts = agiprobot_split(out / "npy", mode, classes)
        assert chosen == by_split[split]
        # millimetres, every label within the scheme, every point a label
        assert all(np.abs(p).max() > 100 for p in points)
        assert counts.sum() == sum(len(p) for p in points)
        expected = np.sum([r["class_counts"] for r in rows if r["split"] == split], axis=0)
        assert np.array_equal(counts, expected)
