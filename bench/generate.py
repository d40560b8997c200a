"""Dataset throughput and peak memory of `motorfactory generate` for the shipped configurations,
at two dataset sizes (peak memory must stay flat as N grows), on all cores.

Usage: python3 bench/generate.py [--configs synmotor,zivid] [--sizes 20,100] [--jobs 2]
Builds the release binary itself; writes into a temporary folder; needs /usr/bin/time.
"""
import argparse
import os
import re
import subprocess
import tempfile


def run(binary, config, n, jobs, out):
    cmd = ["/usr/bin/time", "-v", binary, "generate", "--config", config, "-n", str(n),
           "--jobs", str(jobs), "--out", out, "--quiet"]
    err = subprocess.run(cmd, check=True, capture_output=True, text=True).stderr
    wall = re.search(r"Elapsed \(wall clock\) time.*: (?:(\d+):)?(\d+):([\d.]+)", err)
    h, m, s = wall.groups()
    seconds = int(h or 0) * 3600 + int(m) * 60 + float(s)
    rss = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", err).group(1))
    return seconds, rss / 1024


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--configs", default="synmotor,zivid")
    p.add_argument("--sizes", default="20,100")
    p.add_argument("--jobs", type=int, default=2)
    args = p.parse_args()
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    subprocess.run(["cargo", "build", "--release", "-q"], cwd=root, check=True)
    binary = os.path.join(root, "target", "release", "motorfactory")
    with tempfile.TemporaryDirectory() as tmp:
        for config in args.configs.split(","):
            for n in [int(x) for x in args.sizes.split(",")]:
                seconds, rss = run(binary, os.path.join(root, "configs", f"{config}.toml"), n, args.jobs,
                                   os.path.join(tmp, f"{config}-{n}"))
                print(f"{config}: {n} samples in {seconds:.1f} s = {n / seconds:.2f} samples/s, "
                      f"peak RSS {rss:.0f} MB ({args.jobs} jobs, files written)")


if __name__ == "__main__":
    main()
