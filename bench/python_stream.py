"""Samples per second through the Python package against the Rust core, in one run.

For each configuration, over samples 1..N: the Rust core's time to make each in memory (`cargo
bench -p scene --bench sample_times`, one sample at a time on all threads) and `Generator[i]`'s,
in turns, sample by sample (the median of their differences: what the package adds), the Rust
core's samples per second, and a `DataLoader(MotorDataset(config), num_workers=2)`'s over the
same samples. With `--stream N`, the peak resident memory (this process and its workers) over N
samples streamed through `MotorStream` with 2 workers.

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


def paired_times(config: str, n: int) -> tuple:
    """For each of samples 1..n, the Rust core's time and `Generator[i]`'s, in turns (the Rust
    benchmark as a second process, given one index at a time), seconds."""
    rust = subprocess.Popen(
        ["cargo", "bench", "-q", "-p", "scene", "--bench", "sample_times", "--", config, "-"],
        stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True,
    )
    gen = mf.Generator(config, samples=n + 1)
    gen[0]
    rust_times, gen_times = [], []

    def rust_time(i):
        rust.stdin.write(f"{i}\n")
        rust.stdin.flush()
        m = re.fullmatch(r"sample (\d+): (\S+) s\n", rust.stdout.readline())
        if m is None or int(m.group(1)) != i:
            raise RuntimeError(f"the Rust benchmark did not time sample {i}")
        return float(m.group(2))

    def gen_time(i):
        t = time.perf_counter()
        gen[i]
        return time.perf_counter() - t

    for i in range(1, n + 1):
        # who goes first alternates: the second finds the caches as the first left them
        if i % 2:
            rust_times.append(rust_time(i))
            gen_times.append(gen_time(i))
        else:
            gen_times.append(gen_time(i))
            rust_times.append(rust_time(i))
    rust.stdin.close()
    rust.wait()
    return rust_times, gen_times


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
    print("| config | Rust, in memory (/s) | DataLoader, 2 workers (/s) | ratio | "
          "Generator[i] (ms, median) | Rust (ms, median) | added (ms, median of the differences) |")
    print("|---|---|---|---|---|---|---|")
    for config in args.configs.split(","):
        rust, gen = paired_times(config, args.samples)
        rate = loader_rate(config, args.samples)
        rust_rate = len(rust) / sum(rust)
        added = statistics.median(g - r for g, r in zip(gen, rust))
        print(f"| {config} | {rust_rate:.1f} | {rate:.1f} | {rate / rust_rate:.2f} | "
              f"{statistics.median(gen) * 1e3:.1f} | {statistics.median(rust) * 1e3:.1f} | "
              f"{added * 1e3:+.1f} |", flush=True)
    if args.stream:
        peak_streaming(args.configs.split(",")[0], args.stream)


if __name__ == "__main__":
    main()
