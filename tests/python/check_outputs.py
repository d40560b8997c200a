"""Reads motorfactory's outputs back with independent readers (numpy, Open3D) and checks them
against each other and against scan.json.

Usage: python3 tests/python/check_outputs.py SCAN_DIR MOTOR_DIR
"""
import json
import sys

import numpy as np
import open3d as o3d

from checks import check, report


def main(scan_dir, motor_dir):
    summary = json.load(open(f"{scan_dir}/scan.json"))
    n = summary["points"]

    table = np.load(f"{scan_dir}/cloud.npy")
    check("npy shape", table.shape == (n, 7) and table.dtype == np.float32, table.shape)
    xyz = table[:, :3]
    labels = table[:, 6]
    check("npy labels are classes", np.all(labels == np.round(labels)) and labels.min() >= 0)
    check("npy colours in 0..1", table[:, 3:6].min() >= 0 and table[:, 3:6].max() <= 1)

    npz = np.load(f"{scan_dir}/cloud.npz")
    check("npz arrays", sorted(npz.files) == ["instance", "intensity", "label", "normal", "rgb", "snr", "wear", "xyz"], npz.files)
    rgb = npz["rgb"]
    check("npz rgb N x 3 uint8", rgb.shape == (n, 3) and rgb.dtype == np.uint8, (rgb.shape, rgb.dtype))
    check("npy colours are the npz rgb", np.allclose(table[:, 3:6], rgb / 255.0, atol=1e-6))
    check("colours vary within a class", len(np.unique(rgb[labels == labels[0]], axis=0)) > 10)
    check("npz xyz equals npy xyz", np.array_equal(npz["xyz"], xyz))
    check("npz labels", np.array_equal(npz["label"].astype(np.float32), labels) and npz["label"].dtype == np.uint16)
    check("npz normals are unit", np.allclose(np.linalg.norm(npz["normal"], axis=1), 1, atol=1e-4))
    check("npz instance dtype", npz["instance"].dtype == np.uint32)
    snr = npz["snr"]
    check("npz snr float32 0..255", snr.dtype == np.float32 and snr.shape == (n,) and snr.min() >= 0 and snr.max() <= 255)

    # the binary PLY's vertices as numpy reads them from the header's property list
    raw = open(f"{scan_dir}/cloud.ply", "rb").read()
    header, body = raw.split(b"end_header\n", 1)
    kinds = {"float": "<f4", "uchar": "u1", "uint16": "<u2", "int": "<i4"}
    props = [line.split()[1:] for line in header.decode().splitlines() if line.startswith("property")]
    vertices = np.frombuffer(body, dtype=np.dtype([(name, kinds[kind]) for kind, name in props]), count=n)
    check("ply snr is the npz snr", np.array_equal(vertices["snr"], snr))
    check("ply intensity is the npz intensity", np.array_equal(vertices["intensity"], npz["intensity"]))
    wear = npz["wear"]
    check("npz wear float32 0..1", wear.dtype == np.float32 and wear.shape == (n,) and wear.min() >= 0 and wear.max() <= 1)
    check("ply wear is the npz wear", np.array_equal(vertices["wear"], wear))

    check("ply labels are the npz labels", np.array_equal(vertices["class"], npz["label"])
          and np.array_equal(vertices["instance"], npz["instance"]))
    # Open3D's tensor reader keeps the labels, in the types the header declares
    tensor = o3d.t.io.read_point_cloud(f"{scan_dir}/cloud.ply").point
    check("open3d tensor ply labels", "class" in tensor and "instance" in tensor, list(tensor))
    if "class" in tensor and "instance" in tensor:
        check("open3d tensor ply class", np.array_equal(tensor["class"].numpy().ravel(), npz["label"]))
        check("open3d tensor ply instance", np.array_equal(tensor["instance"].numpy().ravel(), npz["instance"]))
    for name in ["cloud.ply", "cloud.pcd", "cloud_ascii.pcd"]:
        pc = o3d.io.read_point_cloud(f"{scan_dir}/{name}")
        pts = np.asarray(pc.points)
        check(f"open3d {name} count", len(pts) == n, f"{len(pts)} vs {n}")
        check(f"open3d {name} points", len(pts) == n and np.allclose(pts, xyz, atol=1e-5))
        check(f"open3d {name} normals", pc.has_normals() and np.allclose(np.asarray(pc.normals), npz["normal"], atol=1e-5))
        check(f"open3d {name} colours", pc.has_colors() and np.allclose(np.asarray(pc.colors), rgb / 255.0, atol=1e-6))

    depth = np.load(f"{scan_dir}/depth.npy")
    h, w = summary["pixels"]["height"], summary["pixels"]["width"]
    check("depth shape", depth.shape == (h, w), depth.shape)
    check("depth valid pixels", int(np.count_nonzero(~np.isnan(depth))) == summary["pixels"]["valid"])
    png = np.asarray(o3d.io.read_image(f"{scan_dir}/depth.png")).astype(np.float64) * summary["depth_png_metres_per_unit"]
    valid = ~np.isnan(depth)
    check("depth png matches depth npy", png.shape == depth.shape and np.all(np.abs(png[valid] - depth[valid]) <= 0.51e-4))
    check("depth png zero where no data", np.all(png[~valid] == 0))
    rgb_png = np.asarray(o3d.io.read_image(f"{scan_dir}/rgb.png"))
    check("rgb png H x W x 3 uint8", rgb_png.shape == (h, w, 3) and rgb_png.dtype == np.uint8, rgb_png.shape)
    # each point's colour is its pixel's: the cloud's colours are among the image's
    image_colours = set(map(tuple, rgb_png.reshape(-1, 3)))
    check("points' rgb come from the rgb png", all(tuple(c) in image_colours for c in rgb[:2000]))
    wear_png = np.asarray(o3d.io.read_image(f"{scan_dir}/wear.png"))
    check("wear png H x W uint8", wear_png.shape == (h, w) and wear_png.dtype == np.uint8, wear_png.shape)
    labels_png = np.asarray(o3d.io.read_image(f"{scan_dir}/labels.png"))
    check("label png holds the cloud's classes", set(np.unique(labels)) <= set(np.unique(labels_png).astype(float)))

    for ext in ["obj", "stl", "ply"]:
        mesh = o3d.io.read_triangle_mesh(f"{motor_dir}/motor.{ext}")
        check(f"open3d motor.{ext} triangles", len(mesh.triangles) > 1000, len(mesh.triangles))
    attrs = json.load(open(f"{motor_dir}/attributes.json"))
    for part in attrs["attributes"]["parts"]:
        mesh = o3d.io.read_triangle_mesh(f"{motor_dir}/{part['name']}.ply")
        check(f"open3d {part['name']} edge-manifold and closed",
              mesh.is_edge_manifold(allow_boundary_edges=False) and mesh.is_orientable())
    bolt = o3d.io.read_triangle_mesh(f"{motor_dir}/side_bolt_1.ply")
    check("open3d: a bolt is watertight", bolt.is_watertight())
    total = sum(p["triangles"] for p in attrs["attributes"]["parts"])
    ply = o3d.io.read_triangle_mesh(f"{motor_dir}/motor.ply")
    check("motor.ply triangles match attributes.json", len(ply.triangles) == total, f"{len(ply.triangles)} vs {total}")

    return report("python readers")


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], sys.argv[2]))
