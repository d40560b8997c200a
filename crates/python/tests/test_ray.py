"""motorfactory on a real local Ray cluster (two CPUs): the datasource's rows are the
generator's samples in whatever order the blocks come, a read task whose worker is killed is
retried and gives the same rows, the fixed-size blocks are those MotorDataset draws, and a
dataset written by Ray tasks is the folder `motorfactory generate` writes, byte for byte, even
when a task's worker dies mid-shard. Skipped where Ray is not installed (an optional extra)."""

import json
import logging
import os
import pathlib

from conftest import dataset_files
import signal
import subprocess
import threading
import time

import numpy as np
import pytest

ray = pytest.importorskip("ray")

import motorfactory as mf  # noqa: E402
from motorfactory.ray import POINT_COLUMNS, read_motorfactory, write  # noqa: E402

OVERRIDES = {"sensor.sampling": "blueSubsample4x4"}
N, SEED = 6, 3


@pytest.fixture(scope="module")
def cluster():
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False, logging_level=logging.WARNING)
    ray.data.DataContext.get_current().enable_progress_bars = False
    yield
    ray.shutdown()


@pytest.fixture(scope="module")
def samples():
    g = mf.Generator("default", seed=SEED, overrides=OVERRIDES, samples=N)
    return [g[i] for i in range(N)]


def assert_rows_are_the_samples(rows, samples, columns=POINT_COLUMNS):
    assert sorted(int(r["index"]) for r in rows) == list(range(len(samples)))
    for row in rows:
        sample = samples[int(row["index"])]
        for c in columns:
            assert row[c].dtype == sample[c].dtype, c
            assert np.array_equal(row[c], sample[c]), (int(row["index"]), c)


def test_the_rows_are_the_generators_samples_in_any_block_order(cluster, samples):
    ds = read_motorfactory("default", n=N, seed=SEED, overrides=OVERRIDES, parallelism=3)
    rows = list(ds.randomize_block_order(seed=1).iter_rows())
    assert_rows_are_the_samples(rows, samples)
    for row in rows:
        assert json.loads(row["json"]) == samples[int(row["index"])]["json"]


def test_n_may_exceed_the_configurations_own_count(cluster, samples):
    few = dict(OVERRIDES, samples=2)
    rows = list(read_motorfactory("default", n=4, seed=SEED, overrides=few).iter_rows())
    assert_rows_are_the_samples(rows, samples[:4])


def kill_a_worker_running(task: str, work):
    """Runs `work` in a thread, kills (SIGKILL) the first worker process seen running `task`
    (a worker names itself after the task it runs), and returns what `work` returned."""
    out = {}
    running = threading.Thread(target=lambda: out.update(result=work()))
    running.start()
    killed = None
    deadline = time.monotonic() + 300
    while killed is None and running.is_alive() and time.monotonic() < deadline:
        found = subprocess.run(["pgrep", "-f", f"ray::{task}"], capture_output=True, text=True)
        pids = [int(p) for p in found.stdout.split()]
        if pids:
            os.kill(pids[0], signal.SIGKILL)
            killed = pids[0]
        time.sleep(0.02)
    running.join(600)
    assert killed is not None, f"no {task} task was seen running"
    return out["result"]


def test_a_worker_killed_mid_read_is_retried_and_gives_the_same_rows(cluster, samples):
    ds = read_motorfactory(
        "default", n=N, seed=SEED, overrides=OVERRIDES, parallelism=2, columns=["index", "xyz"]
    )
    rows = kill_a_worker_running("ReadMotorfactory", lambda: list(ds.iter_rows()))
    assert_rows_are_the_samples(rows, samples, columns=["xyz"])


@pytest.fixture(scope="module")
def generated(cli, tmp_path_factory) -> pathlib.Path:
    """The folder `motorfactory generate` writes for the tests' configuration."""
    out = tmp_path_factory.mktemp("cli") / "data"
    subprocess.run(
        [cli, "generate", "-n", str(N), "--seed", str(SEED), "--quiet", "--out", out,
         "--set", "sensor.sampling=blueSubsample4x4"],
        check=True,
    )
    return out


def test_write_is_what_generate_writes_byte_for_byte(cluster, generated, tmp_path):
    counts = write("default", N, tmp_path / "data", SEED, overrides=OVERRIDES, shards=3)
    assert counts["made"] == N and counts["skipped"] == 0
    files = dataset_files(tmp_path / "data")
    assert "manifest.jsonl" in files and len(files) > N
    assert files == dataset_files(generated)


def test_a_shard_whose_worker_dies_is_redone_alone_and_the_folder_is_the_same(
    cluster, generated, tmp_path
):
    out = tmp_path / "data"
    counts = kill_a_worker_running(
        "_write_one", lambda: write("default", N, out, SEED, overrides=OVERRIDES, shards=2)
    )
    # every sample made once in all, by the first tries or by the retried one
    assert counts["made"] + counts["skipped"] == N
    assert dataset_files(out) == dataset_files(generated)


def test_blocks_of_points_are_those_motor_dataset_draws(cluster):
    torch_data = pytest.importorskip("motorfactory.torch")
    ds = read_motorfactory(
        "default",
        n=4,
        seed=SEED,
        overrides=OVERRIDES,
        split="train",
        num_points=512,
        columns=["index", "xyz", "label", "instance"],
    )
    reference = torch_data.MotorDataset(
        "default", split="train", num_points=512, seed=SEED, overrides=OVERRIDES, samples=4
    )
    expected = {reference.indices[k]: reference[k] for k in range(len(reference))}
    seen = []
    for batch in ds.iter_torch_batches(batch_size=2):
        assert set(batch) == {"index", "xyz", "label", "instance"}
        assert batch["xyz"].shape[1:] == (512, 3)
        for k, index in enumerate(batch["index"].tolist()):
            seen.append(index)
            assert np.array_equal(batch["xyz"][k].numpy(), expected[index]["xyz"].numpy())
            for c in ("label", "instance"):
                assert np.array_equal(batch[c][k].numpy().astype(np.int64), expected[index][c].numpy())
    assert sorted(seen) == sorted(expected)


def test_bad_arguments_are_refused_in_the_users_words(cluster):
    with pytest.raises(ValueError, match="columns \\['points'\\] are not allowed"):
        read_motorfactory("default", n=2, columns=["xyz", "points"])
    with pytest.raises(ValueError, match="num_points = 0 is not allowed"):
        read_motorfactory("default", n=2, num_points=0)
