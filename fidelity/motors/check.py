"""The motor fidelity check: our motors against the original add-on, part by part, without
Blender. Each case of reference/cases.json (made by reference.py with the add-on as an oracle) is
built with `motorfactory motor`, and each add-on part is compared with ours as the oracle's
compare.py compares them: the largest deviation of a bounding-box face (mm) and the silhouette
IoU along x, y and z (0.25 mm pixels); and their depth maps along x, y and z from both sides
(depth.py: 0.5 mm pixels): of the pixels where both see a surface, the share within 0.5 mm,
the least of the six views. Each of our parts is also loaded as trimesh loads an STL
(vertices welded) and checked to be watertight with consistent winding, and as Open3D loads it,
checked to be watertight in Open3D's sense (edge- and vertex-manifold, and no two triangles
intersecting: shells that touch or overlap fail). The table goes into docs/fidelity-motors.md.

Usage: python3 fidelity/motors/check.py BINARY [--oracle DIR] [--write]
Without --write the check fails (exit 1) when the figures differ from the documented table, so
the table always says what the code builds; with --write it rewrites the table. Needs numpy,
trimesh, open3d and the oracle's folder (for compare.py: the rasteriser and part mapping).
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

import numpy as np
import open3d as o3d
import trimesh

import depth

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
DOC = os.path.join(ROOT, "docs", "fidelity-motors.md")
DEPTH_GOAL = 0.90
BEGIN, END = "<!-- table: fidelity/motors/check.py --write -->", "<!-- end of table -->"


def reference(case):
    """The add-on's measurements of `case`: {part: (bbox, {axis: silhouette}, {axis: depth maps})}."""
    data = np.load(os.path.join(HERE, "reference", case + ".npz"))
    parts = {}
    for key in data.files:
        if key.startswith("bbox/"):
            part = key[5:]
            sil = {}
            for axis in "xyz":
                h, w = data["shape/%s/%s" % (part, axis)]
                bits = np.unpackbits(data["mask/%s/%s" % (part, axis)])[: h * w]
                origin = tuple(int(o) for o in data["origin/%s/%s" % (part, axis)])
                sil[axis] = (bits.reshape(h, w).astype(bool), origin)
            maps = {axis: (data["depth/%s/%s" % (part, axis)],
                           tuple(int(o) for o in data["depth_origin/%s/%s" % (part, axis)]))
                    for axis in "xyz"}
            parts[part] = (data[key], sil, maps)
    return parts


def rows(binary, case, args, compare):
    """The compared rows of one case, the whole motor last."""
    ref = reference(case)
    with tempfile.TemporaryDirectory() as tmp:
        cmd = [binary, "motor", "--format", "stl", "--out", tmp]
        cmd += [x for s in args for x in ("--set", s)]
        subprocess.run(cmd, check=True, capture_output=True)
        files = [f for f in sorted(os.listdir(tmp)) if f.endswith(".stl") and f != "motor.stl"]
        ours = {f[:-4]: compare.load_tris(os.path.join(tmp, f), 100.0) for f in files}
        tight, solid = {}, {}
        for f in files:
            welded = trimesh.load(os.path.join(tmp, f), process=True)
            tight[f[:-4]] = bool(welded.is_watertight and welded.is_winding_consistent)
            mesh = o3d.io.read_triangle_mesh(os.path.join(tmp, f))
            mesh.remove_duplicated_vertices()
            solid[f[:-4]] = bool(mesh.is_watertight())
    abb = {k: tuple(v[0]) for k, v in ref.items() if k != "Motor"}
    obb = {k: compare.bbox(v) for k, v in ours.items()}
    mapping = {k: [o for o in compare.PART_MAP[k] if o in ours] for k in abb if k in compare.PART_MAP}
    mapping.update(compare.match_bolts(abb, obb))
    order = [k for k in compare.ORDER if k in abb]
    order += sorted((k for k in abb if k.startswith("Bolt_")), key=lambda s: int(s.split("_")[1]))
    order.append("Motor")
    out = []
    for part in order:
        names = list(ours) if part == "Motor" else mapping.get(part, [])
        (lo, hi), sil, maps = ref[part]
        if not names:
            out.append((part, "(none)", float("inf"), 0.0, 0.0, 0.0, 0.0, False, False))
            continue
        tris = np.concatenate([ours[n] for n in names])
        mn, mx = compare.bbox(tris)
        dev = float(max(np.abs(mn - lo).max(), np.abs(mx - hi).max()) * 10)
        ious = [compare.iou(sil[a], compare.union([compare.silhouette(ours[n], a) for n in names]))
                for a in "xyz"]
        # the least agreement of the six views (each axis from below and from above)
        agree = 1.0
        for a in "xyz":
            ours_maps, origin = depth.depth_maps(tris, a)
            for side in range(2):
                share, _ = depth.agreement((maps[a][0][side:side + 1], maps[a][1]),
                                           (ours_maps[side:side + 1], origin))
                agree = min(agree, share)
        label = "all parts" if part == "Motor" else " + ".join(names)
        out.append((part, label, dev, *ious, agree, all(tight[n] for n in names),
                    all(solid[n] for n in names)))
    return out


def table(binary, compare):
    cases = json.load(open(os.path.join(HERE, "reference", "cases.json")))["cases"]
    lines = ["| case | add-on part | ours | dev mm | IoU x | IoU y | IoU z | within 1 mm, IoU ≥ 0.90 "
             "| depth ≤ 0.5 mm | watertight (trimesh) | watertight (Open3D) |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    met = total = sealed = solids = deep = 0
    for case, info in cases.items():
        for part, ours, dev, ix, iy, iz, agree, tight, solid in rows(binary, case, info["set"], compare):
            goal = 0.95 if part == "Motor" else 0.90
            ok = dev <= 1.0 and min(ix, iy, iz) >= goal if part != "Motor" else min(ix, iy, iz) >= goal
            if part != "Motor":
                met += ok
                sealed += tight
                solids += solid
                deep += agree >= DEPTH_GOAL
                total += 1
            lines.append("| %s | %s | %s | %.1f | %.2f | %.2f | %.2f | %s | %.2f | %s | %s |"
                         % (case, part, ours, dev, ix, iy, iz, "yes" if ok else "no", agree,
                            "yes" if tight else "no", "yes" if solid else "no"))
    lines.append("")
    lines.append("Parts watertight with consistent winding after welding (trimesh): %d of %d." % (sealed, total))
    lines.append("Parts watertight in Open3D (no touching or overlapping shells): %d of %d." % (solids, total))
    lines.append("Parts within 1 mm and IoU ≥ 0.90 on every axis: %d of %d." % (met, total))
    lines.append("Parts whose depth agrees within 0.5 mm on at least %d %% of the pixels of every view: "
                 "%d of %d." % (round(100 * DEPTH_GOAL), deep, total))
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("binary")
    ap.add_argument("--oracle", default=os.path.join(ROOT, "..", "shared", "reference", "addon-oracle"))
    ap.add_argument("--write", action="store_true")
    a = ap.parse_args()
    sys.path.insert(0, os.path.abspath(a.oracle))
    import compare
    new = table(os.path.abspath(a.binary), compare)
    doc = open(DOC).read()
    head, rest = doc.split(BEGIN)
    old, tail = rest.split(END)
    if a.write:
        open(DOC, "w").write(head + BEGIN + "\n" + new + "\n" + END + tail)
        print(new.splitlines()[-1])
    elif old.strip() != new.strip():
        import difflib
        sys.stdout.writelines(difflib.unified_diff(old.strip().splitlines(True), new.strip().splitlines(True),
                                                   "docs/fidelity-motors.md", "built now"))
        sys.exit("the motors differ from docs/fidelity-motors.md: run fidelity/motors/check.py --write")
    else:
        print("fidelity: " + new.splitlines()[-1])


if __name__ == "__main__":
    main()
