"""Checks a dataset's BOP scenes (`output.bop`) as a BOP user's tools see them.

    python check_bop.py DATASET

Every scene under DATASET/bop/{train_pbr,val_pbr}/: each annotated object's model (read by
Open3D) placed by its `cam_R_m2c` and `cam_t_m2c` and ray-cast by Open3D through every pixel's
centre (undistorted by OpenCV where the camera has `dist_coeffs`) must give its `mask` and, where
`mask_visib` says it is seen, the depth image's depth (a depth sensor's measured depth: the
view's own depth image); `mask_visib` lies in `mask`, the class
image says the object's `obj_id` there, and every `scene_gt_info` figure and `models_info` entry
is recomputed from the files.
"""

import json
import sys
from pathlib import Path

import cv2
import numpy as np
import open3d as o3d
from PIL import Image

# Pixels a mask may differ by from Open3D's silhouette: rays grazing an edge shared by two
# triangles, which two float32 ray casters may call either way.
GRAZING = 0.002
# Depth a visible pixel may differ by from Open3D's, mm: half a step of 0.1 mm and float32.
DEPTH_MM = 0.1


def load(path):
    return json.loads(Path(path).read_text())


def box(mask):
    ys, xs = np.nonzero(mask)
    if len(xs) == 0:
        return [-1, -1, -1, -1]
    return [int(xs.min()), int(ys.min()), int(xs.max() - xs.min() + 1), int(ys.max() - ys.min() + 1)]


def rays(camera, width, height):
    """Unit directions through every pixel's centre in the camera frame, H x W x 3."""
    k = np.array(camera["cam_K"], np.float64).reshape(3, 3)
    u, v = np.meshgrid(np.arange(width, dtype=np.float64), np.arange(height, dtype=np.float64))
    pixels = np.stack([u.ravel(), v.ravel()], 1)
    if "dist_coeffs" in camera:
        dist = np.array(camera["dist_coeffs"], np.float64)
        criteria = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 100, 1e-12)
        xy = cv2.undistortPoints(pixels.reshape(-1, 1, 2), k, dist, None, None, None, criteria)
        xy = xy.reshape(-1, 2)
    else:
        xy = np.stack([(pixels[:, 0] - k[0, 2]) / k[0, 0], (pixels[:, 1] - k[1, 2]) / k[1, 1]], 1)
    d = np.concatenate([xy, np.ones((len(xy), 1))], 1)
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    return d.reshape(height, width, 3)


def brute_diameter(points):
    best = 0.0
    for i in range(0, len(points), 512):
        d = np.linalg.norm(points[i : i + 512, None, :] - points[None, :, :], axis=2)
        best = max(best, float(d.max()))
    return best


def check_scene(root, sample, scene, worst):
    cameras = load(scene / "scene_camera.json")
    gts = load(scene / "scene_gt.json")
    infos = load(scene / "scene_gt_info.json")
    models_info = load(scene / "models" / "models_info.json")
    assert cameras.keys() == gts.keys() == infos.keys(), scene
    models = {}
    for im, gt in gts.items():
        camera = cameras[im]
        rgb = next((scene / "rgb").glob(f"{int(im):06d}.*"))
        width, height = Image.open(rgb).size
        depth = np.asarray(Image.open(scene / "depth" / f"{int(im):06d}.png")).astype(np.float64)
        depth_mm = depth * camera["depth_scale"]
        assert depth.shape == (height, width), (depth.shape, width, height)
        stem = rgb.name.split(".")[0]
        dirs = rays(camera, width, height).astype(np.float32)
        # the dataset's own class image of the same view, named by the sample's JSON
        files = sample["views"][int(im)]["files"]
        label_file = next(f for f in files if f.endswith("_labels.png"))
        classes = np.asarray(Image.open(root / label_file))
        # a depth sensor's depth is measured (noisy): the view's own depth image; a colour
        # camera's is exact, checked against Open3D's below
        ideal = sample["sensor"]["model"]["kind"] == "ideal"
        if not ideal:
            own = next(f for f in files if f.endswith("_depth.png"))
            assert (np.asarray(Image.open(root / own)) == depth).all(), (scene, im)
        assert len(gt) == len(infos[im]), scene
        for g, (entry, info) in enumerate(zip(gt, infos[im])):
            inst = entry["instance_id"]
            if inst not in models:
                mesh = o3d.io.read_triangle_mesh(str(scene / "models" / f"instance_{inst:06d}.ply"))
                assert mesh.has_vertex_normals() and len(mesh.triangles) > 0, inst
                v = np.asarray(mesh.vertices)
                mi = models_info[str(inst)]
                lo, size = v.min(0), v.max(0) - v.min(0)
                for axis, a in enumerate("xyz"):
                    assert abs(mi[f"min_{a}"] - lo[axis]) < 1e-3, (mi, lo)
                    assert abs(mi[f"size_{a}"] - size[axis]) < 1e-3, (mi, size)
                exact = brute_diameter(np.unique(v, axis=0))
                assert exact * 0.997 <= mi["diameter"] <= exact * 1.0001, (mi["diameter"], exact)
                # centred on its box
                assert np.abs(lo + size / 2).max() < 1e-3, lo + size / 2
                models[inst] = mesh
            mesh = models[inst]
            r = np.array(entry["cam_R_m2c"], np.float64).reshape(3, 3)
            t = np.array(entry["cam_t_m2c"], np.float64)
            assert np.abs(r @ r.T - np.eye(3)).max() < 1e-5 and np.linalg.det(r) > 0, r
            v = np.asarray(mesh.vertices) @ r.T + t
            tri = o3d.t.geometry.TriangleMesh()
            tri.vertex.positions = o3d.core.Tensor(v.astype(np.float32))
            tri.triangle.indices = o3d.core.Tensor(np.asarray(mesh.triangles).astype(np.int32))
            caster = o3d.t.geometry.RaycastingScene()
            caster.add_triangles(tri)
            origin = np.zeros_like(dirs)
            ray = o3d.core.Tensor(np.concatenate([origin, dirs], 2))
            hit = caster.cast_rays(ray)["t_hit"].numpy()
            silhouette = np.isfinite(hit)
            mask = np.asarray(Image.open(scene / "mask" / f"{stem}_{g:06d}.png")) > 0
            visib = np.asarray(Image.open(scene / "mask_visib" / f"{stem}_{g:06d}.png")) > 0
            differ = int((mask != silhouette).sum())
            assert differ <= max(2, GRAZING * silhouette.sum()), (scene, im, g, differ, silhouette.sum())
            worst["mask"] = max(worst["mask"], differ / max(1, silhouette.sum()))
            assert not (visib & ~mask).any(), (scene, im, g)
            both = visib & silhouette
            z = (hit * dirs[..., 2])[both]
            if ideal and both.any():
                dz = float(np.abs(z - depth_mm[both]).max())
                assert dz <= DEPTH_MM, (scene, im, g, dz)
                worst["depth"] = max(worst["depth"] or 0.0, dz)
            assert (classes[visib] == entry["obj_id"]).all(), (scene, im, g, entry["obj_id"])
            all_px, visib_px = int(mask.sum()), int(visib.sum())
            expected = {
                "bbox_obj": box(mask),
                "bbox_visib": box(visib),
                "px_count_all": all_px,
                "px_count_valid": int((mask & (depth > 0)).sum()),
                "px_count_visib": visib_px,
            }
            for key, value in expected.items():
                assert info[key] == value, (scene, im, g, key, info[key], value)
            fract = visib_px / all_px if all_px else 0.0
            assert abs(info["visib_fract"] - fract) < 1e-12, (info["visib_fract"], fract)
            worst["objects"] += 1
        worst["images"] += 1
    return worst


def main():
    root = Path(sys.argv[1])
    bop = root / "bop"
    camera = load(bop / "camera.json")
    scenes = sorted(p for split in ("train_pbr", "val_pbr") for p in (bop / split).glob("*") if p.is_dir())
    assert scenes, "no BOP scenes"
    first = load(scenes[0] / "scene_camera.json")["0"]["cam_K"]
    assert [camera["fx"], camera["cx"], camera["fy"], camera["cy"]] == [first[0], first[2], first[4], first[5]]
    worst = {"mask": 0.0, "depth": None, "objects": 0, "images": 0}
    rows = {}
    for line in (root / "manifest.jsonl").read_text().splitlines():
        row = json.loads(line)
        rows[row["index"]] = row
    for scene in scenes:
        sample = load(root / rows[int(scene.name)]["json"])
        check_scene(root, sample, scene, worst)
    print(
        f"BOP: {len(scenes)} scenes, {worst['images']} images, {worst['objects']} objects: "
        f"masks equal Open3D's silhouettes but {worst['mask']:.4%} of a mask's pixels at most, "
        + ("measured depth the views' own, " if worst["depth"] is None else f"depth within {worst['depth']:.3f} mm, ")
        + "scene_gt_info and models_info recomputed"
    )


if __name__ == "__main__":
    main()
