"""The Ray Train example runs as documented: a TorchTrainer of two workers reads its training
split from the Ray Data source, lowers the loss, validates on the validation split and leaves
its weights in a checkpoint. Skipped where Ray is not installed (an optional extra)."""

import json
import math
import pathlib
import subprocess
import sys

import pytest

pytest.importorskip("ray")
torch = pytest.importorskip("torch")

import motorfactory as mf  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[3]


def test_the_ray_train_example_trains_on_two_workers_reading_the_datasource():
    done = subprocess.run(
        [sys.executable, ROOT / "examples/python/train_segmentation_ray.py",
         "--samples", "24", "--epochs", "1", "--batch", "4"],
        check=True, capture_output=True, text=True,
    )
    summary = json.loads(done.stdout.strip().splitlines()[-1])
    print(done.stdout)
    gen = mf.Generator("default", samples=24)
    # the two workers read the training split between them, each sample once, in equal
    # shares (Ray Train's split leaves out what does not divide evenly)
    assert summary["workers"] == 2
    train = len(gen.indices("train"))
    assert summary["samples_read"] == train - train % 2
    assert math.isfinite(summary["first_loss"]) and summary["last_loss"] < summary["first_loss"]
    assert 0.0 <= summary["miou"] <= 1.0
    held_out = summary["validation_samples"]
    assert held_out and all(gen.split_of(i) == "validation" for i in held_out), held_out
    weights = torch.load(pathlib.Path(summary["checkpoint"]) / "model.pt")
    assert any(name.endswith("weight") for name in weights)
