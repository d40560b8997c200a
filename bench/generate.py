"""Dataset throughput and peak memory of `motorfactory generate` for the shipped configurations,
at two dataset sizes (peak memory must stay flat as N grows), on all cores.

Usage: python3 bench/generate.py [--configs synmotor,zivid] [--sizes 20,100] [--jobs 2]
Builds the release binary itself; writes each dataset into a temporary folder and deletes it once
measured (100 Zivid samples take 12.5 GB); needs /usr/bin/time.
"""
import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile


def run(binary, config, n, jobs, out):
    cmd = ["/usr/bin/time", "-v", binary, "generate", "--config", config, "-n", str(n),
           "--jobs", str(jobs), "--out", out, "--quiet"]
    done = subprocess.run(cmd, capture_output=True, text=True)
    shutil.rmtree(out, ignore_errors=True)  # a 100-sample Zivid dataset is 12.5 GB
    if done.returncode != 0:
        said = re.split(r"Command exited with|\tCommand being timed", done.stderr)[0].strip()
        sys.exit(f"{' '.join(cmd[2:])} failed (exit {done.returncode}): {said}")
    err = done.stderr
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
