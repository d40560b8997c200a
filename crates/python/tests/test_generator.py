"""Dataset samples in memory: the values `motorfactory generate` writes, deterministic, and bad
input raised with the CLI's words."""

import json
import subprocess

import numpy as np
import pytest
from conftest import dataset_files

import motorfactory as mf

ARRAYS = ["xyz", "normal", "intensity", "snr", "rgb", "label", "instance", "wear"]


@pytest.mark.parametrize("config", ["default", "synmotor"])
def test_samples_are_what_generate_writes(cli, tmp_path, config):
    out = tmp_path / config
    subprocess.run(
        [cli, "generate", "--config", config, "-n", "3", "--quiet", "--out", out,
         "--set", 'output.formats=["npz"]'],
        check=True,
    )
    gen = mf.Generator(config, overrides={"output.formats": ["npz"]})
    rows = [json.loads(line) for line in (out / "manifest.jsonl").read_text().splitlines()]
    assert [r["index"] for r in rows] == [0, 1, 2]
    for row in rows:
        sample = gen[row["index"]]
        assert sample["json"] == json.loads((out / row["json"]).read_text())
        assert len(sample["views"]) == len(row["files"])
        for view, file in zip(sample["views"], row["files"]):
            written = np.load(out / file)
            for name in ARRAYS:
                assert view[name].dtype == written[name].dtype, name
                np.testing.assert_array_equal(view[name], written[name], err_msg=name)
        for name in ARRAYS:
            np.testing.assert_array_equal(sample[name], sample["views"][0][name])


def test_samples_are_deterministic_and_independent_of_order():
    a, b = mf.Generator("synmotor", seed=5), mf.Generator("synmotor", seed=5)
    late = b[3]
    early = a[3]
    for name in ARRAYS:
        np.testing.assert_array_equal(early[name], late[name])
    assert early["json"] == late["json"]
    other = mf.Generator("synmotor", seed=6)[3]
    assert not np.array_equal(other["xyz"], early["xyz"])


def test_configs_dicts_and_overrides():
    gen = mf.Generator({"samples": 7, "camera": {"views": 2}}, overrides={"seed": 3})
    assert len(gen) == 7 and gen[-1]["json"]["index"] == 6
    sample = gen[0]
    assert len(sample["views"]) == 2 and sample["json"]["seed"] != 0
    assert "views = 2" in gen.config
    assert gen.classes[:3] == ["background", "cover", "gear_container"]
    train, validation = gen.indices("train"), gen.indices("validation")
    assert sorted(train + validation) == list(range(7))
    assert mf.Generator("default", overrides={"output.scheme": "wacv6"}).classes[-1] == "bolt"


@pytest.mark.parametrize(
    "call, error, message",
    [
        (lambda: mf.Generator("nope"), ValueError, "config nope: no such file, and no built-in configuration"),
        (lambda: mf.Generator("/no/such.toml"), ValueError, "config /no/such.toml: no such file"),
        (lambda: mf.Generator(overrides={"camera.viewz": 2}), ValueError, "camera.viewz"),
        (lambda: mf.Generator(overrides={"camera.views": 0}), ValueError, "camera.views = 0 is not allowed"),
        (lambda: mf.Generator({"camera": {"views": "two"}}), ValueError, "camera.views"),
        (lambda: mf.Generator(samples=5)[5], IndexError, "sample 5 is out of range: the configuration has 5 samples"),
        (lambda: mf.Generator().indices("test"), ValueError, 'split = "test" is not allowed'),
        (lambda: mf.Generator(config=3.5), ValueError, "config is a configuration's name"),
    ],
)
def test_bad_input_raises_with_the_clis_words(call, error, message):
    with pytest.raises(error) as raised:
        call()
    assert message in str(raised.value)


def test_cli_and_package_refuse_a_config_alike(cli, tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("[camera]\nviews = 0\n")
    run = subprocess.run([cli, "generate", "--config", bad, "--out", tmp_path / "o"],
                         capture_output=True, text=True)
    assert run.returncode == 2
    with pytest.raises(ValueError) as raised:
        mf.Generator(str(bad))
    assert str(raised.value) in run.stderr


def test_write_is_what_generate_writes_for_the_whole_and_for_shards(cli, tmp_path):
    sets = {"sensor.sampling": "blueSubsample4x4"}
    subprocess.run(
        [cli, "generate", "-n", "3", "--quiet", "--out", tmp_path / "cli",
         "--set", "sensor.sampling=blueSubsample4x4"],
        check=True,
    )
    counts = mf.write(tmp_path / "whole", "default", samples=3, overrides=sets)
    assert counts["made"] == 3 and counts["skipped"] == 0 and counts["empty"] == []
    assert dataset_files(tmp_path / "whole") == dataset_files(tmp_path / "cli")
    # two shards, the second finishing the dataset; then a resume finds nothing left to make
    first = mf.write(tmp_path / "shards", "default", samples=3, overrides=sets, shard=(0, 2))
    second = mf.write(tmp_path / "shards", "default", samples=3, overrides=sets, shard=(1, 2))
    assert (first["made"], second["made"]) == (2, 1)
    assert dataset_files(tmp_path / "shards") == dataset_files(tmp_path / "cli")
    again = mf.write(tmp_path / "shards", "default", samples=3, overrides=sets, resume=True)
    assert (again["made"], again["skipped"]) == (0, 3)
    with pytest.raises(ValueError, match=r"shard = \(2, 2\) is not allowed"):
        mf.write(tmp_path / "bad", shard=(2, 2))
    assert not (tmp_path / "bad").exists()


def test_hall_passes_are_what_generate_writes(cli, tmp_path):
    out = tmp_path / "hall"
    keys = {"lidar.preset": "velodyne-vlp16", "lidar.revolutions": 2, "lidar.formats": ["npz"]}
    subprocess.run(
        [cli, "generate", "--config", "hall", "-n", "3", "--quiet", "--out", out,
         "--set", "lidar.preset=velodyne-vlp16", "--set", "lidar.revolutions=2",
         "--set", 'lidar.formats=["npz"]'],
        check=True,
    )
    gen = mf.Generator("hall", overrides=keys)
    rows = [json.loads(line) for line in (out / "manifest.jsonl").read_text().splitlines()]
    for row in rows:
        sample = gen[row["index"]]
        assert sample["json"] == json.loads((out / row["json"]).read_text())
        assert (sample["json"]["hall"], sample["json"]["revolution"]) == divmod(row["index"], 2)
        written = np.load(out / row["files"][0])
        np.testing.assert_array_equal(sample["xyz"], written["xyz_noisy"])
        for name in ["ring", "time", "echo", "label", "instance", "rgb", "intensity"]:
            assert sample[name].dtype == written[name].dtype, name
            np.testing.assert_array_equal(sample[name], written[name], err_msg=name)
        assert sample["ring"].max() == 15 and 0 <= sample["time"].min() < sample["time"].max() < 0.1
    assert gen.classes[:3] == ["background", "motor", "carrier"]
