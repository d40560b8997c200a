"""Figures of the hall's LiDAR passes: for each preset, the first pass of the `hall`
configuration (world frame) seen obliquely from above, its points coloured by ring (left) and
by class (right, the label scheme's colours).

    python3 lidar_figures.py MOTORFACTORY OUT_DIR [WIDTH]

writes OUT_DIR/lidar-{preset}.png.
"""

import colorsys
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw

PRESETS = ["velodyne-hdl64e-s2", "velodyne-hdl32e", "velodyne-vlp16", "ibeo-lux", "generic-lidar"]


def view(xyz, width, height):
    """Pixel columns, rows and depth of an oblique view: turned 30 degrees about z, tilted 50
    degrees from above, fitted to the hall's floor."""
    a, t = np.radians(-30.0), np.radians(50.0)
    x = xyz[:, 0] * np.cos(a) - xyz[:, 1] * np.sin(a)
    y = xyz[:, 0] * np.sin(a) + xyz[:, 1] * np.cos(a)
    z = xyz[:, 2]
    u, v, depth = x, y * np.cos(t) + z * np.sin(t), -y * np.sin(t) + z * np.cos(t)
    scale = min(width / 27.0, height / 19.0)
    return width / 2 + u * scale, height / 2 - v * scale, depth


def panel(cols, rows, depth, colours, width, height, title, big=None):
    """The points drawn far to near, 2x2 pixels (3x3 where `big`)."""
    image = np.full((height, width, 3), 255, np.uint8)
    big = np.zeros(len(cols), bool) if big is None else big
    order = np.argsort(-depth)
    c, r, b = cols[order].astype(int), rows[order].astype(int), big[order]
    keep = (c >= 1) & (c < width - 2) & (r >= 1) & (r < height - 2)
    c, r, b, colour = c[keep], r[keep], b[keep], colours[order][keep]
    for dc in (-1, 0, 1):
        for dr in (-1, 0, 1):
            at = b | ((dc >= 0) & (dr >= 0))
            image[r[at] + dr, c[at] + dc] = colour[at]
    out = Image.fromarray(image)
    ImageDraw.Draw(out).text((8, 6), title, fill=(0, 0, 0))
    return out


def main():
    binary, out = sys.argv[1], Path(sys.argv[2])
    width = int(sys.argv[3]) if len(sys.argv) > 3 else 520
    height = width * 3 // 4
    out.mkdir(parents=True, exist_ok=True)
    for preset in PRESETS:
        with tempfile.TemporaryDirectory() as tmp:
            folder = Path(tmp) / "hall"
            subprocess.run(
                [binary, "generate", "--config", "hall", "-n", "1", "--quiet", "--out", str(folder),
                 "--set", f"lidar.preset={preset}", "--set", "lidar.frame=world",
                 "--set", 'lidar.formats=["npz"]'],
                check=True,
            )
            classes = json.loads((folder / "labels.json").read_text())["classes"]
            (npz_path,) = folder.glob("*/*.npz")
            scan = np.load(npz_path)
            xyz, ring, label = scan["xyz_noisy"], scan["ring"], scan["label"]
        rings = int(ring.max()) + 1
        ring_colour = np.array(
            [[int(255 * c) for c in colorsys.hsv_to_rgb(0.8 * k / max(rings - 1, 1), 0.9, 0.85)]
             for k in range(rings)], np.uint8)
        class_colour = np.array([c["color"] for c in classes], np.uint8)
        class_colour[0] = (185, 185, 185)  # the background grey, so that the labelled stand out
        cols, rows, depth = view(xyz, width, height)
        left = panel(cols, rows, depth, ring_colour[ring], width, height,
                     f"{preset}: {len(xyz)} returns, {rings} rings")
        right = panel(cols, rows, depth, class_colour[np.minimum(label, len(classes) - 1)],
                      width, height, "by class (objects9): motor orange, carrier blue, background grey",
                      big=label > 0)
        sheet = Image.new("RGB", (2 * width + 4, height), (200, 200, 200))
        sheet.paste(left, (0, 0))
        sheet.paste(right, (width + 4, 0))
        sheet.save(out / f"lidar-{preset}.png", optimize=True)
        print(out / f"lidar-{preset}.png")


if __name__ == "__main__":
    main()
