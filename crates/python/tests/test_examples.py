"""The Python examples run as documented: training lowers the loss; inspecting writes its PNG;
PPO plans views and is scored on held-out motors."""

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


def test_the_view_planning_example_trains_ppo_and_scores_it_on_held_out_motors(tmp_path):
    png = tmp_path / "ppo.png"
    out = run("train_view_planning.py", "--steps", "250", "--motors", "2", "--points", "64",
              "--plot", str(png))
    summary = json.loads(out.strip().splitlines()[-1])
    assert summary["steps"] == 250 and summary["episodes"] == 25 and summary["held_out_motors"] == 2
    scores = summary["coverage_after_views"]
    assert set(scores) == {"PPO, PointNet extractor", "random views",
                           "random views not taken before", "greedy next-best view"}
    assert all(0.3 < s <= 1.0 for s in scores.values()), scores
    assert scores["greedy next-best view"] > scores["random views"]
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
