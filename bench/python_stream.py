"""Samples per second through the Python package against the Rust core, in one run.

For each configuration: the Rust benchmark's samples per second in memory (`cargo bench -p scene
--bench samples`, one sample at a time on all threads), `Generator[i]` called in turn (its
median time over the Rust median: what the package adds), and a
`DataLoader(MotorDataset(config), num_workers=2)`'s samples per second. With `--stream N`, the
peak resident memory (this process and its workers) over N samples streamed through
`MotorStream` with 2 workers.

    python bench/python_stream.py --samples 200 --stream 10000    # in the package's venv
"""

import argparse
import re
import resource
import statistics
import subprocess
import time

import torch
from torch.utils.data import DataLoader

import motorfactory as mf
from motorfactory.torch import MotorDataset, MotorStream


def rust_seconds(config: str) -> float:
    """The Rust benchmark's median time per sample, seconds."""
    out = subprocess.run(
        ["cargo", "bench", "-q", "-p", "scene", "--bench", "samples", "--", f"sample/{config}$"],
        check=True, capture_output=True, text=True,
    ).stdout
    unit = {"ms": 1e-3, "µs": 1e-6, "s": 1.0}
    m = re.search(r"time:\s+\[\S+ \S+ (\S+) (ms|µs|s) ", out)
    if m is None:
        raise RuntimeError(f"no time in the benchmark's output:\n{out}")
    return float(m.group(1)) * unit[m.group(2)]


def generator_seconds(config: str, n: int) -> float:
    """`Generator[i]`'s median time per call, seconds."""
    gen = mf.Generator(config, samples=n + 1)
    gen[0]
    times = []
    for i in range(1, n + 1):
        t = time.perf_counter()
        gen[i]
        times.append(time.perf_counter() - t)
    return statistics.median(times)


def loader_rate(config: str, n: int) -> float:
    """Samples per second of a DataLoader over MotorDataset with 2 workers."""
    data = MotorDataset(config, split=None, samples=n)
    loader = DataLoader(data, batch_size=None, num_workers=2)
    it = iter(loader)
    next(it)  # the workers' start
    t = time.perf_counter()
    count = sum(1 for _ in it)
    return count / (time.perf_counter() - t)


def peak_streaming(config: str, n: int) -> float:
    """Peak resident memory, MiB, of this process and of its workers over n streamed samples."""
    loader = DataLoader(MotorStream(config, count=n), batch_size=None, num_workers=2)
    t = time.perf_counter()
    count = sum(1 for _ in loader)
    rate = count / (time.perf_counter() - t)
    own = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    workers = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024
    print(f"{config}: {count} samples streamed at {rate:.1f}/s; peak resident memory "
          f"{own:.0f} MiB (main process), {workers:.0f} MiB (largest worker)")
    return max(own, workers)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--configs", default="default,synmotor")
    ap.add_argument("--samples", type=int, default=200)
    ap.add_argument("--stream", type=int, default=0, help="samples to stream for peak memory")
    args = ap.parse_args()
    torch.set_num_threads(1)
    print(f"| config | Rust, in memory (/s) | DataLoader, 2 workers (/s) | ratio | "
          f"Generator[i] (ms) | Rust (ms) | added (ms) |")
    print("|---|---|---|---|---|---|---|")
    for config in args.configs.split(","):
        rust = rust_seconds(config)
        gen = generator_seconds(config, args.samples)
        rate = loader_rate(config, args.samples)
        print(f"| {config} | {1 / rust:.1f} | {rate:.1f} | {rate * rust:.2f} | "
              f"{gen * 1e3:.1f} | {rust * 1e3:.1f} | {(gen - rust) * 1e3:+.1f} |", flush=True)
    if args.stream:
        peak_streaming(args.configs.split(",")[0], args.stream)


if __name__ == "__main__":
    main()
