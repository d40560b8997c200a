"""The interreflection figure of docs/sensors.md: a 90° inside corner 0.6 m before a Zivid 2+ MR60
(the M60's optics, binning 2×2), matte grey and polished stainless steel, seen from above (a 2 cm slab of rows
at the corner's middle height). On steel the walls mirror each other's stripes: points move along
their rays and float between the walls; Zivid's reflection filter (on in the preset) removes most.

Usage: python3 fidelity/sensor/interreflection.py target/release/motorfactory docs/img/interreflection.png
Needs: pip install numpy matplotlib
"""
import subprocess
import sys
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def corner_stl(path):
    """Two walls 12 cm deep and 20 cm high meeting at a vertical edge at the origin, 90° apart,
    opening towards -y."""
    d = 0.12 / np.sqrt(2)
    h = 0.2
    walls = [((0, 0), (-d, -d)), ((d, -d), (0, 0))]
    lines = ["solid corner"]
    for (x0, y0), (x1, y1) in walls:
        a, b, c, e = (x0, y0, 0), (x1, y1, 0), (x1, y1, h), (x0, y0, h)
        for tri in ((a, b, c), (a, c, e)):
            lines += ["facet normal 0 0 0", "outer loop"]
            lines += [f"vertex {p[0]} {p[1]} {p[2]}" for p in tri]
            lines += ["endloop", "endfacet"]
    lines.append("endsolid corner")
    Path(path).write_text("\n".join(lines) + "\n")


def scan(binary, mesh, material, out):
    subprocess.run(
        [binary, "scan", "--mesh", f"{mesh}@{material}", "--sensor", "zivid-2plus-mr60",
         "--sampling", "by2x2", "--look-at", "0.03,-0.6,0.1,0,0,0.1", "--frame", "world",
         "--format", "npy", "--out", str(out)],
        check=True, stdout=subprocess.DEVNULL)
    cloud = np.load(next(Path(out).glob("*.npy")))
    return cloud[np.abs(cloud[:, 2] - 0.1) < 0.01]


def main():
    binary, figure = sys.argv[1], sys.argv[2]
    with tempfile.TemporaryDirectory() as tmp:
        mesh = Path(tmp) / "corner.stl"
        corner_stl(mesh)
        clouds = {m: scan(binary, mesh, m, Path(tmp) / m) for m in ("matte-grey", "stainless-steel")}
    fig, axes = plt.subplots(1, 2, figsize=(9, 4.2), sharex=True, sharey=True)
    d = 120 / np.sqrt(2)
    for ax, (material, c) in zip(axes, clouds.items()):
        ax.plot([-d, 0, d], [-d, 0, -d], color="0.75", lw=4, zorder=0)
        ax.scatter(c[:, 0] * 1000, c[:, 1] * 1000, s=0.4, color="tab:blue", zorder=1)
        ax.set_title(f"{material}: {len(c)} points")
        ax.set_xlabel("x, mm")
        ax.set_aspect("equal")
    axes[0].set_ylabel("y (away from the camera), mm")
    fig.suptitle("A 90° inside corner 0.6 m before a Zivid 2+ M60, seen from above")
    fig.tight_layout()
    fig.savefig(figure, dpi=110)


if __name__ == "__main__":
    main()
