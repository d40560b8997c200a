"""Side-by-side renders of the add-on's motor and ours for the same case, for docs/.

Usage (in the oracle's venv, which has bpy, numpy, trimesh and pillow):
    python fidelity/motors/render.py BINARY CASE OUT.png [--oracle DIR]

Builds CASE (a name in the oracle's cases.json) with the add-on in bpy (the oracle's
run_case.py) and with BINARY (`motorfactory motor`, the parameters mapped by the oracle's
to_set.py), and draws both from the same oblique view: a z-buffer of all parts, Lambert-shaded,
each part in its class colour (bolts grey), the add-on on the left.
"""
import argparse
import json
import os
import shlex
import subprocess
import sys
import tempfile

import numpy as np
import trimesh
from PIL import Image

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
SIZE = 560
# add-on part name prefix or our part name prefix -> colour
COLOURS = [
    (("Bottom", "pole_pot"), (150, 160, 175)),
    (("Magnet", "magnet"), (90, 90, 100)),
    (("Rotor", "armature"), (190, 120, 60)),
    (("Charger", "electric_connection"), (70, 130, 200)),
    (("Gear_Container", "gear_container"), (110, 180, 110)),
    (("Cover", "cover"), (220, 200, 90)),
    (("Lower_Inner_Gear", "Upper_Inner_Gear", "Inner_Gear", "lower_gear", "upper_gear", "gear"),
     (200, 110, 160)),
    (("Bolt", "side_bolt", "cover_bolt"), (120, 120, 120)),
]


def colour(name):
    for prefixes, rgb in COLOURS:
        if any(name == p or name.startswith(p + "_") or name.startswith(p) for p in prefixes):
            return np.array(rgb, float)
    return np.array((200, 200, 200), float)


def view_matrix():
    """An oblique view: from the -y side (the cover of type A at orientation 0), a little above."""
    az, el = np.radians(-60.0), np.radians(25.0)
    forward = -np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
    right = np.cross(forward, [0, 0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    return np.stack([right, up, -forward])


def render(parts, frame):
    """parts: [(name, triangles (n, 3, 3) in cm)]; frame: (centre, half-extent) shared by both."""
    centre, half = frame
    R = view_matrix()
    img = np.full((SIZE, SIZE, 3), 255.0)
    depth = np.full((SIZE, SIZE), -np.inf)
    light = np.array([0.3, 0.5, 0.8])
    light /= np.linalg.norm(light)
    scale = (SIZE / 2 - 10) / half
    for name, tris in parts:
        v = (tris - centre) @ R.T
        n = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])
        norm = np.linalg.norm(n, axis=1)
        # two-sided: a face wound the wrong way (the add-on has some) is drawn as seen
        keep = norm > 1e-12
        v, n = v[keep], n[keep] / norm[keep, None]
        n *= np.sign(n[:, 2:3] + 1e-30)
        shade = 0.35 + 0.65 * np.clip(n @ light, 0, 1)
        rgb = colour(name)
        px = np.stack([SIZE / 2 + v[..., 0] * scale, SIZE / 2 - v[..., 1] * scale], -1)
        for t in range(len(v)):
            p, z = px[t], v[t, :, 2]
            x0, y0 = np.floor(p.min(0)).astype(int)
            x1, y1 = np.ceil(p.max(0)).astype(int)
            x0, y0, x1, y1 = max(x0, 0), max(y0, 0), min(x1, SIZE - 1), min(y1, SIZE - 1)
            if x1 < x0 or y1 < y0:
                continue
            xs, ys = np.meshgrid(np.arange(x0, x1 + 1) + 0.5, np.arange(y0, y1 + 1) + 0.5)
            (ax, ay), (bx, by), (cx, cy) = p
            det = (by - cy) * (ax - cx) + (cx - bx) * (ay - cy)
            if abs(det) < 1e-12:
                continue
            l0 = ((by - cy) * (xs - cx) + (cx - bx) * (ys - cy)) / det
            l1 = ((cy - ay) * (xs - cx) + (ax - cx) * (ys - cy)) / det
            l2 = 1 - l0 - l1
            inside = (l0 >= 0) & (l1 >= 0) & (l2 >= 0)
            zz = l0 * z[0] + l1 * z[1] + l2 * z[2]
            sub = depth[y0:y1 + 1, x0:x1 + 1]
            hit = inside & (zz > sub)
            sub[hit] = zz[hit]
            img[y0:y1 + 1, x0:x1 + 1][hit] = rgb * shade[t]
    return img.astype(np.uint8)


def load(folder, scale):
    out = []
    for f in sorted(os.listdir(folder)):
        if f.endswith(".stl") and f.lower() != "motor.stl":
            m = trimesh.load(os.path.join(folder, f), process=False)
            out.append((f[:-4], np.asarray(m.triangles) * scale))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("binary")
    ap.add_argument("case")
    ap.add_argument("out")
    ap.add_argument("--oracle", default=os.path.join(ROOT, "..", "shared", "reference", "addon-oracle"))
    a = ap.parse_args()
    oracle = os.path.abspath(a.oracle)
    with tempfile.TemporaryDirectory() as tmp:
        subprocess.run([sys.executable, os.path.join(oracle, "run_case.py"), a.case, tmp],
                       check=True, capture_output=True)
        cmd = subprocess.run([sys.executable, os.path.join(oracle, "to_set.py"), a.case],
                             check=True, capture_output=True, text=True).stdout.split()
        ours_dir = os.path.join(tmp, "ours")
        args = cmd[cmd.index("motor") + 1: cmd.index("--out")]
        subprocess.run([os.path.abspath(a.binary), "motor", *args, "--out", ours_dir],
                       check=True, capture_output=True)
        addon, ours = load(os.path.join(tmp, a.case), 1.0), load(ours_dir, 100.0)
    allv = np.concatenate([t.reshape(-1, 3) for _, t in addon + ours])
    centre = 0.5 * (allv.min(0) + allv.max(0))
    R = view_matrix()
    half = np.abs((allv - centre) @ R.T)[:, :2].max()
    left, right = render(addon, (centre, half)), render(ours, (centre, half))
    gap = np.full((SIZE, 12, 3), 255, np.uint8)
    Image.fromarray(np.concatenate([left, gap, right], 1)).save(a.out, optimize=True)
    print(a.out)


if __name__ == "__main__":
    main()
