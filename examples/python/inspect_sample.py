"""Makes a dataset sample and a scan in memory, saves the motor's meshes, and plots both with
matplotlib into one PNG: the sample's cropped cloud seen from above, coloured by label, and the
scan's depth image.

    python examples/python/inspect_sample.py out/inspect   # writes out/inspect/inspect.png
"""

import argparse
import pathlib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import motorfactory as mf  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("out", type=pathlib.Path, help="folder for the motor's meshes and the PNG")
    ap.add_argument("--config", default="default")
    ap.add_argument("--index", type=int, default=0)
    args = ap.parse_args()

    gen = mf.Generator(args.config)
    sample = gen[args.index]
    params = sample["json"]["motor"]["params"]
    print(f"sample {args.index}: {len(sample['xyz'])} points, motor type {params['type']}")

    # the same motor on its own, saved and scanned with a Zivid 2+ M60 from 0.5 m
    motor = mf.motor(params)
    motor.save(args.out / "motor", formats=["ply"], replace=True)
    meshes = [(p.vertices, p.triangles, p.class_id, p.instance) for p in motor.parts]
    scan = mf.scan(meshes, sensor="zivid-2plus-m60", eye=(0.15, -0.35, 0.35),
                   target=(0.0, 0.0, 0.05), sampling="blueSubsample2x2", material="black-pa66")
    print(f"scan: {scan}")

    fig, (left, right) = plt.subplots(1, 2, figsize=(12, 5))
    xyz, label = sample["xyz"], sample["label"]
    order = np.argsort(xyz[:, 2])
    left.scatter(xyz[order, 0], xyz[order, 1], c=label[order], s=0.2, cmap="tab10",
                 vmin=0, vmax=9)
    left.set_aspect("equal")
    left.set_title(f"sample {args.index} from above, by label", fontsize=8)
    # a legend of the classes present, in the scatter's colours
    colours = plt.get_cmap("tab10")
    handles = [plt.Line2D([], [], marker="o", linestyle="", color=colours(c / 9), label=gen.classes[c])
               for c in np.unique(label)]
    left.legend(handles=handles, fontsize=7, markerscale=1.5, loc="upper right")
    print(f"legend: {', '.join(h.get_label() for h in handles)}")
    image = right.imshow(scan.depth, cmap="viridis")
    right.set_title("scan depth (m)")
    fig.colorbar(image, ax=right, shrink=0.8)
    args.out.mkdir(parents=True, exist_ok=True)
    png = args.out / "inspect.png"
    fig.savefig(png, dpi=120, bbox_inches="tight")
    print(f"wrote {png}")


if __name__ == "__main__":
    main()
