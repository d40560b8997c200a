"""The Python examples run as documented: training lowers the loss; inspecting writes its PNG."""

import json
import pathlib
import subprocess
import sys

import motorfactory as mf

ROOT = pathlib.Path(__file__).resolve().parents[3]


def run(script: str, *args: str) -> str:
    done = subprocess.run([sys.executable, ROOT / "examples/python" / script, *args],
                          check=True, capture_output=True, text=True)
    return done.stdout


def test_training_lowers_the_loss():
    out = run("train_segmentation.py", "--steps", "60", "--batch", "4")
    summary = json.loads(out.strip().splitlines()[-1])
    print(out)
    assert summary["steps"] == 60
    assert summary["last_loss"] < 0.7 * summary["first_loss"], summary
    assert 0.0 <= summary["miou"] <= 1.0
    # it validates on the validation split, which its training stream never yields
    gen = mf.Generator("default")
    held_out = summary["validation_samples"]
    assert held_out and all(gen.split_of(i) == "validation" for i in held_out), held_out


def test_inspecting_a_sample_writes_its_png(tmp_path):
    out = run("inspect_sample.py", str(tmp_path))
    png = tmp_path / "inspect.png"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert (tmp_path / "motor" / "attributes.json").is_file()
    assert "points" in out
    legend = next(line for line in out.splitlines() if line.startswith("legend: "))
    assert "background" in legend and len(legend.split(", ")) >= 3, legend
