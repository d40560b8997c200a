"""Two builds of motorfactory against each other: each dataset made by both, interleaved round by
round so that the machine's drift hits both alike; medians of samples per second and of peak
memory, and the ratio new / old.

Usage: python3 bench/compare.py OLD_BINARY NEW_BINARY [--configs default:100,zivid:10]
       [--rounds 3] [--jobs 2]
Each dataset goes into a temporary folder, deleted once measured; needs /usr/bin/time.
"""
import argparse
import statistics
import tempfile

from generate import run


def main():
    p = argparse.ArgumentParser()
    p.add_argument("old")
    p.add_argument("new")
    p.add_argument("--configs", default="default:100,synmotor:100,zivid:10")
    p.add_argument("--rounds", type=int, default=3)
    p.add_argument("--jobs", type=int, default=2)
    args = p.parse_args()
    print(f"{'config':>10} {'n':>5} {'old samples/s':>14} {'new samples/s':>14} {'new/old':>8} "
          f"{'old MB':>8} {'new MB':>8}")
    for item in args.configs.split(","):
        config, n = item.split(":")
        n = int(n)
        rates = {"old": [], "new": []}
        peaks = {"old": [], "new": []}
        for _ in range(args.rounds):
            for name in ("old", "new"):
                with tempfile.TemporaryDirectory() as tmp:
                    seconds, mb = run(getattr(args, name), config, n, args.jobs, f"{tmp}/ds")
                rates[name].append(n / seconds)
                peaks[name].append(mb)
        old, new = (statistics.median(rates[k]) for k in ("old", "new"))
        print(f"{config:>10} {n:>5} {old:>14.2f} {new:>14.2f} {new / old:>8.3f} "
              f"{statistics.median(peaks['old']):>8.0f} {statistics.median(peaks['new']):>8.0f}",
              flush=True)


if __name__ == "__main__":
    main()
