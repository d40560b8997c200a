"""Reads a LiDAR scan's files back with independent readers (numpy.loadtxt for Blensor's
.numpy table, Open3D and PCL (pcl-tools' converter, which loads with pcl::io) for its PCD pair,
laspy for the LAS, numpy for our NPZ) and checks them against each other, against scan.json's
laser table and against the geometry of a ray.

Usage: python3 tests/python/check_lidar.py SCAN_DIR
(the scan written with --format blensor-numpy,blensor-pcd,npz,las in the head's frame)
"""
import json
import shutil
import subprocess
import sys
import tempfile

import laspy
import numpy as np
import open3d as o3d

from checks import check, report


def pcl_rows(path):
    """The rows of a PCD file as PCL loads it (pcl::io, through pcl-tools' converter to ASCII);
    an empty array where pcl-tools is not installed."""
    if shutil.which("pcl_convert_pcd_ascii_binary") is None:
        check("pcl-tools installed (pcl_convert_pcd_ascii_binary)", False)
        return np.zeros((0, 0))
    with tempfile.TemporaryDirectory() as tmp:
        out = f"{tmp}/ascii.pcd"
        subprocess.run(["pcl_convert_pcd_ascii_binary", path, out, "0"], check=True, capture_output=True)
        lines = open(out).read().splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("DATA")) + 1
    return np.loadtxt(lines[start:], ndmin=2)


def main(scan_dir):
    summary = json.load(open(f"{scan_dir}/scan.json"))
    n, sensor = summary["returns"], summary["sensor"]
    lasers = sensor["lasers"]

    table = np.loadtxt(f"{scan_dir}/scan.numpy")
    check("numpy table: 16 columns a return", table.shape == (n, 16), table.shape)
    t, yaw, pitch, d, dn = table[:, 0], table[:, 1], table[:, 2], table[:, 3], table[:, 4]
    xyz, noisy, idx = table[:, 5:8], table[:, 8:11], table[:, 15].astype(int)

    npz = np.load(f"{scan_dir}/scan.npz")
    check("npz arrays", sorted(npz.files) == sorted(
        ["xyz", "xyz_noisy", "distance", "measured", "ring", "echo", "echoes", "time", "yaw", "label", "instance", "rgb",
         "reflectivity", "intensity"]), npz.files)
    ring = npz["ring"].astype(int)
    check("the ray index is column x lasers + ring", np.array_equal(idx % len(lasers), ring))
    check("npz points are the table's", np.allclose(npz["xyz"], xyz, atol=1e-6) and np.allclose(npz["xyz_noisy"], noisy, atol=1e-6))
    check("distances are the points' norms", np.allclose(np.linalg.norm(xyz, axis=1), d, rtol=1e-5))
    check("measured distances are the noisy points' norms", np.allclose(np.linalg.norm(noisy, axis=1), np.abs(dn), rtol=1e-5))
    elevation = np.radians([lasers[r]["elevation"] for r in ring])
    check("each point lies on its laser's cone", np.allclose(np.arcsin(xyz[:, 2] / d), elevation, atol=1e-4))
    check("pitch is the laser's elevation", np.allclose(pitch, elevation, atol=1e-4))
    column = idx // len(lasers)
    check("yaw is the column's", np.allclose(yaw, np.radians(np.mod(sensor["start"] + column * sensor["resolution"], 360)), atol=1e-5))
    azimuth = np.arctan2(xyz[:, 1], xyz[:, 0])
    check("each point lies at its yaw", np.allclose(np.angle(np.exp(1j * (azimuth - yaw))), 0, atol=1e-4))
    step = sensor["resolution"] / 360 / sensor["rotation"]
    delay = np.array([lasers[r].get("delay", 0.0) for r in ring])
    check("times follow the turn and the firing order", np.allclose(t, column * step + delay, atol=1e-7))
    check("returns within range", d.max() < sensor["max_range"] and d.min() > 0)

    for name, points in [("scan.pcd", xyz), ("scan_noisy.pcd", noisy)]:
        cloud = o3d.t.io.read_point_cloud(f"{scan_dir}/{name}")
        positions = cloud.point.positions.numpy()
        check(f"{name}: Open3D reads every point", positions.shape == (n, 3), positions.shape)
        check(f"{name}: the table's points to 6 decimals", np.allclose(positions, points, atol=1e-5))
        label = cloud.point.label.numpy().ravel()
        check(f"{name}: label is the class", np.array_equal(label, npz["label"]))
        colours = cloud.point.colors.numpy()
        check(f"{name}: colours are the npz rgb", np.array_equal(colours, npz["rgb"]))
        pcl = pcl_rows(f"{scan_dir}/{name}")
        check(f"{name}: PCL reads every point, x y z rgb label", pcl.shape == (n, 5), pcl.shape)
        if pcl.shape == (n, 5):
            check(f"{name}: PCL's points are the table's", np.allclose(pcl[:, :3], points, atol=1e-5))
            packed = (npz["rgb"].astype(np.int64) * [1 << 16, 1 << 8, 1]).sum(1)
            check(f"{name}: PCL's rgb is the packed colour", np.array_equal(pcl[:, 3].astype(np.int64), packed))
            check(f"{name}: PCL's label is the class", np.array_equal(pcl[:, 4], npz["label"]))
    las = laspy.read(f"{scan_dir}/scan.las")
    check("LAS 1.4, point format 7", (str(las.header.version), las.header.point_format.id) == ("1.4", 7),
          (las.header.version, las.header.point_format.id))
    check("LAS: every return", len(las.points) == n, len(las.points))
    check("LAS: the measured points to 0.1 mm", np.abs(np.stack([las.x, las.y, las.z], 1) - noisy).max() <= 5.1e-5)
    check("LAS: classification is the class", np.array_equal(las.classification, npz["label"]))
    check("LAS: point source is the instance", np.array_equal(las.point_source_id, npz["instance"]))
    check("LAS: user data is the ring", np.array_equal(las.user_data, ring))
    check("LAS: GPS time is the firing time", np.allclose(las.gps_time, t, atol=1e-7))
    check("LAS: return numbers are the echoes", np.array_equal(las.return_number, npz["echo"]) and np.array_equal(las.number_of_returns, npz["echoes"]))
    check("LAS: the intensity", np.array_equal(las.intensity, np.round(npz["intensity"].astype(np.float64) * 65535).astype(np.uint16)))
    check("LAS: 16-bit colours", np.array_equal(np.stack([las.red, las.green, las.blue], 1), npz["rgb"].astype(np.uint16) * 257))
    return report("LiDAR outputs")


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:]))
