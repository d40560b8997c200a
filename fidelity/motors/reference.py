"""Makes the compact reference data of the motor fidelity check from the original add-on, run as
an oracle in Blender's `bpy`: per case, each add-on part's bounding box, its silhouettes along
x, y and z (0.25 mm pixels on a grid fixed in space, as the oracle's compare.py draws them) and
its depth maps along x, y and z from both sides (0.5 mm pixels, depth.py). No geometry of the
add-on is kept, only these measurements.

Usage (Python 3.11 with bpy==5.0.1, numpy, trimesh and open3d, as the oracle's README sets up
plus open3d):
    python fidelity/motors/reference.py [--oracle ../shared/reference/addon-oracle] [--random 8]

Cases: the oracle's five named ones (cases.json), and add-on random motors (its own generator,
auto_generate.generate_param, seeds 0, 1, ...) chosen until every gearbox orientation, both
mirror states and every upper-bolt count are covered and at least --random are taken. Random
bolt positions and drive rotations are switched off (the README's known limits), so both sides
build the same motor. Writes fidelity/motors/reference/<case>.npz and cases.json (each case's
add-on parameters as used, and our `motorfactory motor --set` arguments).
"""
import argparse
import json
import os
import random
import subprocess
import sys
import tempfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))


def random_cases(oracle, most_seeds=500, at_least=8):
    """Add-on random parameter sets covering every orientation, mirror and upper-bolt count."""
    sys.path.insert(0, os.path.join(oracle, "addon", "motor_factory"))
    import auto_generate  # the add-on's own generator: pure Python
    wanted = {("orientation", o) for o in ("r0", "r90", "r180", "r270")}
    wanted |= {("mirror", m) for m in (True, False)} | {("bolts", n) for n in "123"}
    wanted |= {("type", t) for t in ("A", "B")}
    cases, seen = {}, set()
    for seed in range(most_seeds):
        random.seed(seed)
        p = auto_generate.generate_param()
        t = "A" if p["mf_Top_Type"].endswith("_A") else "B"
        ext2 = t == "A" and p["mf_Extension_Type_A"] == "mf_Extension_Type_2"
        has = {("orientation", p["mf_Gear_Orientation_2" if ext2 else "mf_Gear_Orientation_1"]),
               ("mirror", p["mf_Mirror"]), ("type", t)}
        if t == "A":
            has.add(("bolts", p["mf_Upper_Bolt_Nummber"]))
        if has <= seen and len(cases) >= at_least:
            continue
        if has <= seen and not (wanted - seen):
            continue
        # bolt positions are integer properties: whole degrees, as the add-on writes drawn ones back
        p.update({k: int(v) for k, v in p.items() if "_Bolt_Position_" in k})
        p.update(mf_Lower_Gear_Bolt_Random=False, mf_Upper_Gear_Bolt_Random=False,
                 mf_Gear_Bolt_Random_B=False, mf_Bolt_Orientation="mf_all_same",
                 mf_Color_Render=False)
        cases["random_%03d" % seed] = p
        seen |= has
        if not (wanted - seen) and len(cases) >= at_least:
            break
    return cases


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--oracle", default=os.path.join(ROOT, "..", "shared", "reference", "addon-oracle"))
    ap.add_argument("--random", type=int, default=8)
    a = ap.parse_args()
    oracle = os.path.abspath(a.oracle)
    sys.path.insert(0, oracle)
    import compare  # the oracle's rasteriser and bounding boxes
    import depth
    from to_set import to_set  # the oracle's parameter mapping

    named = json.load(open(os.path.join(oracle, "cases.json")))
    cases = dict(named)
    cases.update(random_cases(oracle, at_least=a.random))
    out_dir = os.path.join(HERE, "reference")
    os.makedirs(out_dir, exist_ok=True)
    index = {}
    with tempfile.TemporaryDirectory() as tmp:
        for name, params in cases.items():
            subprocess.run([sys.executable, os.path.join(oracle, "run_case.py"), name, tmp,
                            json.dumps(params)], check=True, capture_output=True)
            built = os.path.join(tmp, name)
            used = json.load(open(os.path.join(built, "used_params.json")))
            args, warnings = to_set(used)
            data = {}
            for f in sorted(os.listdir(built)):
                if not f.endswith(".stl"):
                    continue
                part = f[:-4]
                tris = compare.load_tris(os.path.join(built, f))
                lo, hi = compare.bbox(tris)
                data["bbox/" + part] = np.array([lo, hi])
                for axis in compare.AXES:
                    mask, origin = compare.silhouette(tris, axis)
                    data["mask/%s/%s" % (part, axis)] = np.packbits(mask)
                    data["shape/%s/%s" % (part, axis)] = np.array(mask.shape)
                    data["origin/%s/%s" % (part, axis)] = np.array(origin)
                    maps, origin = depth.depth_maps(tris, axis)
                    data["depth/%s/%s" % (part, axis)] = maps
                    data["depth_origin/%s/%s" % (part, axis)] = np.array(origin)
            np.savez_compressed(os.path.join(out_dir, name + ".npz"), **data)
            index[name] = {"set": args, "warnings": warnings, "addon_params": used}
            print("%s: %d parts" % (name, sum(k.startswith("bbox/") for k in data)), flush=True)
    about = {
        "made_by": "fidelity/motors/reference.py",
        "oracle": "MotorFactory add-on 2.2.0 (cold-soda-jay/blenderMotorFactoryVer2.0 at 9d30513), "
                  "transform.rotate sign corrected, in bpy 5.0.1 with the BMesh boolean",
        "bpy": __import__("bpy").app.version_string,
        "pixel_cm": compare.PX,
        "depth_pixel_cm": depth.PX,
        "depth_unit_cm": depth.UNIT,
        "cases": index,
    }
    json.dump(about, open(os.path.join(out_dir, "cases.json"), "w"), indent=1, sort_keys=True)


if __name__ == "__main__":
    main()
