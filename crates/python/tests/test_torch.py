"""PyTorch datasets: the generator's samples as tensors, fixed-size blocks, the same samples
whatever the DataLoader's workers, and no memory growth over a long stream."""

import numpy as np
import pytest
import torch
from torch.utils.data import DataLoader

import motorfactory as mf
from motorfactory.torch import MotorDataset, MotorStream, collate

# quarter-resolution scans: the same pipeline, a quarter of the time
FAST = {"sensor.sampling": "blueSubsample4x4"}


def test_dataset_items_are_the_generators_samples():
    data = MotorDataset("default", split="validation", samples=40, overrides=FAST)
    gen = mf.Generator("default", samples=40, overrides=FAST)
    assert data.indices == gen.indices("validation") and len(data) == len(data.indices) > 0
    item = data[0]
    sample = gen[data.indices[0]]
    assert item["index"] == data.indices[0]
    np.testing.assert_array_equal(item["xyz"].numpy(), sample["xyz"])
    np.testing.assert_array_equal(item["label"].numpy(), sample["label"].astype(np.int64))
    assert item["rgb"].dtype == torch.float32 and float(item["rgb"].max()) <= 1.0


def test_blocks_have_a_fixed_size_and_are_drawn_alike():
    data = MotorDataset("default", samples=6, num_points=2048, normalize=True, overrides=FAST)
    a, b = data[1], data[1]
    assert a["xyz"].shape == (2048, 3) and a["label"].shape == (2048,)
    torch.testing.assert_close(a["xyz"], b["xyz"], rtol=0, atol=0)
    assert abs(float(a["xyz"].norm(dim=1).max()) - 1.0) < 1e-5
    assert float(a["xyz"].mean(dim=0).abs().max()) < 0.1
    with pytest.raises(ValueError, match="num_points = 0 is not allowed"):
        MotorDataset("default", num_points=0)


def batches(loader):
    return [(b["index"].tolist(), b["xyz"].clone(), b["label"].clone()) for b in loader]


def test_workers_do_not_change_the_samples():
    data = MotorDataset("default", samples=10, num_points=1024, overrides=FAST)
    one = batches(DataLoader(data, batch_size=3, num_workers=0))
    two = batches(DataLoader(data, batch_size=3, num_workers=2))
    assert [i for i, _, _ in one] == [i for i, _, _ in two]
    for (_, x1, y1), (_, x2, y2) in zip(one, two):
        assert torch.equal(x1, x2) and torch.equal(y1, y2)


def test_a_stream_makes_every_sample_once_whatever_the_workers():
    stream = MotorStream("default", start=4, count=7, num_points=512, overrides=FAST)
    seen = {}
    for workers in (0, 2):
        loader = DataLoader(stream, batch_size=None, num_workers=workers)
        got = {int(s["index"]): s["xyz"] for s in loader}
        assert sorted(got) == list(range(4, 11)), workers
        for k, xyz in got.items():
            if k in seen:
                assert torch.equal(seen[k], xyz)
            seen[k] = xyz
    # the stream's samples are the generator's, beyond the configuration's count too
    gen = mf.Generator("default", overrides=FAST, samples=2)
    direct = MotorStream("default", start=10, count=1, overrides=FAST)
    (only,) = list(direct)
    np.testing.assert_array_equal(only["xyz"].numpy(), gen.sample_at(10)["xyz"])


def test_a_split_stream_yields_only_its_split_whatever_the_workers():
    gen = mf.Generator("default", overrides=FAST, samples=40)
    want = {"train": [], "validation": []}
    for i in range(40):
        want[gen.split_of(i)].append(i)
    assert want["train"] and want["validation"]
    assert want["validation"] == gen.indices("validation")
    for split in ("validation", "train"):
        stream = MotorStream("default", count=3, num_points=64, overrides=FAST, split=split)
        for workers in (0, 2):
            loader = DataLoader(stream, batch_size=None, num_workers=workers)
            got = sorted(int(s["index"]) for s in loader)
            assert got == want[split][:3], (split, workers, got)
    with pytest.raises(ValueError, match='split = "test" is not allowed'):
        MotorStream("default", split="test")


def test_collate_batches_clouds_of_any_size():
    data = MotorDataset("default", samples=4, overrides=FAST)
    items = [data[0], data[1]]
    batch = collate(items)
    sizes = [len(i["xyz"]) for i in items]
    assert batch["xyz"].shape == (sum(sizes), 3)
    assert batch["batch"].tolist() == [0] * sizes[0] + [1] * sizes[1]
    assert batch["offsets"].tolist() == [0, sizes[0]]
    assert batch["index"].tolist() == [items[0]["index"], items[1]["index"]]


def resident_bytes() -> int:
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * 4096


def test_resident_memory_does_not_grow_over_2000_samples():
    # Resident memory swings by tens of MiB from sample to sample (the scans' buffers differ in
    # size); a leak is a trend, so compare the median of the second 900 samples with the first's.
    stream = iter(MotorStream("default", count=2000, num_points=2048, overrides=FAST))
    for _ in range(200):
        next(stream)
    readings = []
    for k, _ in enumerate(stream):
        if k % 20 == 0:
            readings.append(resident_bytes() / 2**20)
    half = len(readings) // 2
    first, second = np.median(readings[:half]), np.median(readings[half:])
    print(f"resident memory, median over samples 200-1100 {first:.0f} MiB, 1100-2000 {second:.0f} MiB")
    assert second - first < 16, f"{second - first:.1f} MiB"
