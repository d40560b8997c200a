"""Samples per second into PyTorch through Ray Data against the in-process MotorDataset, in one
run: ``read_motorfactory(...).iter_torch_batches()`` on a local Ray cluster of ``--cpus`` CPUs
against a DataLoader over ``MotorDataset`` (no worker processes: the Rust core spreads each
sample over the cores itself), rounds interleaved, medians reported; Ray's start-up (``ray.init``
and the first read, which starts its worker processes) reported apart.

    .venv/bin/pip install "./crates/python[ray]"
    .venv/bin/python bench/ray_stream.py --samples 32 --rounds 3
"""

import argparse
import logging
import statistics
import time

import ray
import torch

from motorfactory.ray import read_motorfactory
from motorfactory.torch import MotorDataset


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--config", default="default")
    ap.add_argument("--samples", type=int, default=32)
    ap.add_argument("--points", type=int, default=2048)
    ap.add_argument("--batch", type=int, default=8)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--cpus", type=int, default=2)
    args = ap.parse_args()
    columns = ["index", "xyz", "label"]

    t = time.perf_counter()
    ray.init(num_cpus=args.cpus, include_dashboard=False, log_to_driver=False, logging_level=logging.WARNING)
    ray.data.DataContext.get_current().enable_progress_bars = False
    started = time.perf_counter() - t

    def through_ray(n: int) -> int:
        ds = read_motorfactory(args.config, n=n, num_points=args.points, columns=columns)
        return sum(len(b["index"]) for b in ds.iter_torch_batches(batch_size=args.batch))

    def in_process(n: int) -> int:
        data = MotorDataset(args.config, split=None, num_points=args.points, samples=n)
        loader = torch.utils.data.DataLoader(data, batch_size=args.batch)
        return sum(len(b["index"]) for b in loader)

    t = time.perf_counter()
    through_ray(args.cpus)
    first = time.perf_counter() - t
    print(f"Ray start-up: ray.init {started:.1f} s, the first read of {args.cpus} samples {first:.1f} s")

    rates = {"ray": [], "in-process": []}
    for r in range(args.rounds):
        for name, run in (("ray", through_ray), ("in-process", in_process)):
            t = time.perf_counter()
            assert run(args.samples) == args.samples
            rates[name].append(args.samples / (time.perf_counter() - t))
            print(f"round {r}: {name} {rates[name][-1]:.2f} samples/s", flush=True)
    ray_rate, own = (statistics.median(rates[k]) for k in ("ray", "in-process"))
    print(
        f"{args.samples} samples of {args.config!r}, {args.points} points, batches of {args.batch}, "
        f"{args.cpus} CPUs: Ray {ray_rate:.2f} samples/s, MotorDataset {own:.2f} samples/s "
        f"(medians of {args.rounds}); Ray / MotorDataset {ray_rate / own:.2f}"
    )
    ray.shutdown()


if __name__ == "__main__":
    main()
