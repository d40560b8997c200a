"""Depth maps of a part along the axes, for the motor fidelity check: on a grid of 0.5 mm pixels
fixed in space (pixel k covers [k * PX, (k + 1) * PX), as the oracle's silhouettes), the
coordinate along the axis of the first surface a ray through the pixel's centre meets coming
from below (near) and from above (far). Rays are cast by Open3D's RaycastingScene (Embree), so
faces count whichever way they are wound.
"""
import numpy as np
import open3d as o3d

PX = 0.05      # pixel size in cm (0.5 mm)
UNIT = 1e-3    # depths are kept in whole 10 µm steps (cm * 1e3)
NONE = np.iinfo(np.int32).min   # a pixel where the ray meets nothing
AXES = "xyz"


def depth_maps(tris, axis):
    """tris: (n, 3, 3) triangles in cm. Returns (maps, origin): maps[0] near and maps[1] far, each
    [v, u] for pixel (origin[0] + u, origin[1] + v) of the plane normal to `axis` ((y, z) for x,
    (x, z) for y, (x, y) for z), int32 in UNIT steps or NONE."""
    a = AXES.index(axis)
    iu, iv = [i for i in range(3) if i != a]
    v = tris.reshape(-1, 3)
    lo, hi = v.min(0), v.max(0)
    u0, v0 = int(np.floor(lo[iu] / PX)), int(np.floor(lo[iv] / PX))
    nu, nv = int(np.ceil(hi[iu] / PX)) - u0 + 1, int(np.ceil(hi[iv] / PX)) - v0 + 1
    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(v.astype(np.float32), np.arange(len(v), dtype=np.uint32).reshape(-1, 3))
    gu, gv = np.meshgrid((u0 + np.arange(nu) + 0.5) * PX, (v0 + np.arange(nv) + 0.5) * PX)
    maps = []
    for start, step in ((lo[a] - 1.0, 1.0), (hi[a] + 1.0, -1.0)):
        rays = np.zeros((nv, nu, 6), np.float32)
        rays[..., iu], rays[..., iv], rays[..., a] = gu, gv, start
        rays[..., 3 + a] = step
        t = scene.cast_rays(o3d.core.Tensor(rays))["t_hit"].numpy()
        hit = np.isfinite(t)
        d = np.full((nv, nu), NONE, np.int32)
        d[hit] = np.round((start + step * t[hit]) / UNIT).astype(np.int32)
        maps.append(d)
    return np.stack(maps), (u0, v0)


def agreement(ref, ours, tolerance_cm=0.05):
    """Of the pixels where both (maps, origin) pairs see a surface, near and far counted apart:
    (the share within `tolerance_cm` of each other, how many pixels)."""
    (ma, oa), (mb, ob) = ref, ours
    u0, v0 = max(oa[0], ob[0]), max(oa[1], ob[1])
    u1 = min(oa[0] + ma.shape[2], ob[0] + mb.shape[2])
    v1 = min(oa[1] + ma.shape[1], ob[1] + mb.shape[1])
    if u1 <= u0 or v1 <= v0:
        return 0.0, 0
    a = ma[:, v0 - oa[1]:v1 - oa[1], u0 - oa[0]:u1 - oa[0]].astype(np.int64)
    b = mb[:, v0 - ob[1]:v1 - ob[1], u0 - ob[0]:u1 - ob[0]].astype(np.int64)
    both = (a != NONE) & (b != NONE)
    n = int(both.sum())
    if not n:
        return 0.0, 0
    return float((np.abs(a - b)[both] <= round(tolerance_cm / UNIT)).sum() / n), n
