"""Ray-casting throughput of motorfactory's caster against Open3D's RaycastingScene (Embree) on
the same mesh and rays, one after the other in one invocation.

Workload: primary rays of a 1944 x 1200 pinhole camera (the Zivid 2 resolution) on a
tessellated sphere-on-plane scene of about 200k and 2M triangles, returning distance, triangle id
and normal, on 2 threads. Rays whose distances differ by more than 1 mm are re-cast in float64
against every triangle (exactly where a ray passes through an edge or a vertex), to say which
caster was right.

Embree 3 in C (bench/embree_peer.c, rtcIntersect16 on the same packets of 16 and rtcIntersect1)
joins them where Debian's libembree-dev is installed: each caster's rate, build and bytes per
triangle, and its hit/miss agreement with ours.

Usage: python3 bench/raycast_peers.py [--threads 2] [--repeats 5] [--sizes 200000,2000000]
[--referee 20] [--rounds 3] (`--referee 0` re-casts every ray where the casters differ, and gives
each caster's agreement with the referee over all rays: rays where they agree count as right;
`--rounds` times motorfactory's packets, Open3D and Embree's packets in turn that many times,
and gives the median of each round's ratios: the machine's speed drifts over minutes)
(`--sizes 20000000` for 20M triangles: about 6 GB of memory, mostly the float64 referee's)
Needs: pip install numpy open3d (and Debian's libusb-1.0-0); builds the Rust side and the Embree
peer itself.
"""
import argparse
import json
import os
import subprocess
import tempfile
import time
from fractions import Fraction

import numpy as np


def scene(triangles):
    """A UV sphere of radius 0.25 m resting on a 1 x 1 m grid plane, ~`triangles` triangles."""
    n = int(np.sqrt(triangles / 4))
    th, ph = np.meshgrid(np.linspace(0, np.pi, n + 1), np.linspace(0, 2 * np.pi, n + 1), indexing="ij")
    sphere = np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], -1).reshape(-1, 3) * 0.25
    sphere[:, 2] += 0.25
    gx, gy = np.meshgrid(np.linspace(-0.5, 0.5, n + 1), np.linspace(-0.5, 0.5, n + 1), indexing="ij")
    plane = np.stack([gx, gy, np.zeros_like(gx)], -1).reshape(-1, 3)

    def grid(offset):
        i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
        a = (i * (n + 1) + j).ravel() + offset
        b, c, d = a + n + 1, a + n + 2, a + 1
        return np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])

    vertices = np.concatenate([sphere, plane]).astype(np.float32)
    tris = np.concatenate([grid(0), grid(len(sphere))]).astype(np.uint32)
    return vertices, tris


def camera_rays(width=1944, height=1200, f=1500.0):
    """Rays of a camera 1 m above the scene, looking down (+z towards the table), in the order a
    scan casts them: 4x4 pixel blocks row by row, each as four 2x2 groups (top left, top right,
    bottom left, bottom right), each group's pixels in the same order. Both casters get the same
    order."""
    u, v = np.meshgrid(np.arange(width, dtype=np.float32), np.arange(height, dtype=np.float32))
    blocks = lambda a: a.reshape(height // 4, 2, 2, width // 4, 2, 2).transpose(0, 3, 1, 4, 2, 5).reshape(-1)
    u, v = blocks(u), blocks(v)
    d = np.stack([(u - width / 2) / f, (v - height / 2) / f, -np.ones_like(u)], -1).reshape(-1, 3)
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    o = np.tile(np.array([0.0, 0.0, 1.0], np.float32), (len(d), 1))
    return np.concatenate([o, d], 1).astype(np.float32)


def open3d_rate(vertices, tris, rays, threads, repeats):
    import open3d as o3d

    start = time.perf_counter()
    rs = o3d.t.geometry.RaycastingScene(nthreads=threads)
    rs.add_triangles(o3d.core.Tensor(vertices), o3d.core.Tensor(tris))
    rays_t = o3d.core.Tensor(rays)
    rs.cast_rays(rays_t[:1], nthreads=threads)  # builds the BVH
    build = time.perf_counter() - start
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        ans = rs.cast_rays(rays_t, nthreads=threads)
        t = ans["t_hit"].numpy()
        ids = ans["primitive_ids"].numpy()
        normals = ans["primitive_normals"].numpy()
        times.append(time.perf_counter() - start)
    times.sort()
    return build, len(rays) / times[0] / 1e6, len(rays) / times[len(times) // 2] / 1e6, t, ids, normals


def embree(root):
    """The Embree peer's binary, compiled from bench/embree_peer.c; None without Embree 3."""
    if not os.path.exists("/usr/include/embree3/rtcore.h"):
        return None
    binary = os.path.join(root, "target", "embree_peer")
    source = os.path.join(root, "bench", "embree_peer.c")
    subprocess.run(["cc", "-O3", "-march=native", source, "-lembree3", "-lpthread", "-lm", "-o", binary], check=True)
    return binary


def first_hit(p, e1, e2, ray):
    """The nearest hit distance of one ray on every triangle (corners `p`, edges `e1` and `e2`
    from the first corner, float64; inf where it misses): Moller-Trumbore in float64, and where
    a triangle's barycentric coordinates lie within 1e-9 of its boundary (a ray through an edge
    or a vertex, where float64's rounding could decide either way) the same test in exact
    rational arithmetic on the float32 inputs, edges included. The referee where the casters
    disagree."""
    o, d = ray[:3].astype(np.float64), ray[3:].astype(np.float64)
    pv = np.cross(d, e2)
    det = np.einsum("ij,ij->i", e1, pv)
    band = 1e-9
    with np.errstate(divide="ignore", invalid="ignore"):  # degenerate triangles: det = 0
        tv = o - p[:, 0]
        u = np.einsum("ij,ij->i", tv, pv) / det
        q = np.cross(tv, e1)
        v = (q @ d) / det
        t = np.einsum("ij,ij->i", e2, q) / det
        hit = (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 0)
        near = (u >= -band) & (v >= -band) & (u + v <= 1 + band) & (t > 0) & (
            (np.abs(u) < band) | (np.abs(v) < band) | (np.abs(1 - u - v) < band))
    for k in np.where(near)[0]:
        hit[k] = exact_hit(p[k], ray)
    return t[hit].min() if hit.any() else np.inf


def exact_hit(corners, ray):
    """Whether `ray` (float32 origin and direction) meets the triangle `corners` at t > 0,
    edges included, in exact rational arithmetic."""
    o, d = ([Fraction(float(x)) for x in ray[k:k + 3]] for k in (0, 3))
    a, b, c = ([Fraction(float(x)) for x in corner] for corner in corners)
    sub = lambda x, y: [x[j] - y[j] for j in range(3)]
    cross = lambda x, y: [x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2], x[0] * y[1] - x[1] * y[0]]
    dot = lambda x, y: sum(x[j] * y[j] for j in range(3))
    e1, e2 = sub(b, a), sub(c, a)
    pv = cross(d, e2)
    det = dot(e1, pv)
    if det == 0:
        return False
    tv = sub(o, a)
    q = cross(tv, e1)
    u, v, t = dot(tv, pv) / det, dot(d, q) / det, dot(e2, q) / det
    return u >= 0 and v >= 0 and u + v <= 1 and t > 0


def referee(vertices, tris, rays, ours, theirs, limit):
    """Rays whose hit distances differ by more than 1 mm (or where only one caster hits),
    re-cast by `first_hit`: (how many differ, how many of the first `limit` (0: all) were
    re-cast, how many of those the re-cast agrees with us on, and with Open3D on)."""
    a, b = (np.where(np.isnan(x), np.inf, x) for x in (ours, theirs))  # a miss is infinitely far
    differ = np.where(~np.isclose(a, b, rtol=0, atol=1e-3) & (np.isfinite(a) | np.isfinite(b)))[0]
    with_us = with_them = 0
    p = vertices[tris].astype(np.float64)
    e1, e2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    judged = differ[:limit] if limit else differ
    for i in judged:
        t = first_hit(p, e1, e2, rays[i])
        with_us += bool(np.isclose(t, a[i], rtol=0, atol=1e-4))  # two misses are close too
        with_them += bool(np.isclose(t, b[i], rtol=0, atol=1e-4))
    return len(differ), len(judged), with_us, with_them


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--repeats", type=int, default=5)
    p.add_argument("--sizes", default="200000,2000000")
    p.add_argument("--referee", type=int, default=20,
                   help="rays where the casters differ to re-cast exactly, per size (0: every one)")
    p.add_argument("--rounds", type=int, default=3,
                   help="rounds of packets, Open3D and Embree's packets in turn, per size (ratios: "
                        "their medians over the rounds, each round's casters timed minutes apart at most)")
    args = p.parse_args()
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    subprocess.run(["cargo", "build", "--release", "-q", "-p", "sensor", "--example", "raycast_peer"], cwd=root, check=True)
    binary = os.path.join(root, "target", "release", "examples", "raycast_peer")
    embree_binary = embree(root)
    rays = camera_rays()
    print(f"{len(rays)} primary rays, {args.threads} threads, best of {args.repeats}")
    with tempfile.TemporaryDirectory() as tmp:
        np.save(f"{tmp}/rays.npy", rays)
        for size in [int(s) for s in args.sizes.split(",")]:
            vertices, tris = scene(size)
            np.save(f"{tmp}/v.npy", vertices)
            np.save(f"{tmp}/t.npy", tris)
            def ours_rate(mode):
                out = subprocess.run([binary, f"{tmp}/v.npy", f"{tmp}/t.npy", f"{tmp}/rays.npy", str(args.threads), str(args.repeats),
                                      f"{tmp}/hits_{mode}.npy", mode], check=True, capture_output=True, text=True).stdout
                return json.loads(out)

            def embree_rate(mode):
                out = subprocess.run([embree_binary, f"{tmp}/v.npy", f"{tmp}/t.npy", f"{tmp}/rays.npy", str(args.threads),
                                      str(args.repeats), f"{tmp}/embree.npy", mode], check=True, capture_output=True, text=True).stdout
                return json.loads(out)

            runs = {mode: ours_rate(mode) for mode in ["single", "packets"]}
            hits = np.load(f"{tmp}/hits_packets.npy")
            same = np.array_equal(hits, np.load(f"{tmp}/hits_single.npy"))
            build, best, median, t, ids, normals = open3d_rate(vertices, tris, rays, args.threads, args.repeats)
            both = np.isfinite(t) & np.isfinite(hits[:, 0])
            agree = np.mean(np.isfinite(t) == np.isfinite(hits[:, 0]))
            t_err = np.max(np.abs(t[both] - hits[both, 0])) if both.any() else 0.0
            n_dot = np.mean(np.abs(np.sum(normals[both] * hits[both, 2:5], 1)) > 0.999)
            differ, judged, with_us, with_them = referee(vertices, tris, rays, hits[:, 0], t, args.referee)
            ours, single = runs["packets"], runs["single"]
            print(f"{len(tris) / 1e3:.0f}k triangles: motorfactory packets of 16 {ours['best_mrays']:.2f} Mrays/s (median {ours['median_mrays']:.2f}), "
                  f"single rays {single['best_mrays']:.2f} (median {single['median_mrays']:.2f}), build {ours['build_s']:.3f} s, "
                  f"tree {ours['bvh_bytes_per_triangle']:.0f} bytes a triangle, "
                  f"packet hits identical to single: {same}; "
                  f"Open3D {best:.2f} Mrays/s (median {median:.2f}, build {build:.3f} s); ratio {ours['best_mrays'] / best:.2f}x; "
                  f"hit/miss agreement {agree:.5f}, max |dt| {t_err:.2e} m, normals agree {n_dot:.4f}; "
                  f"{differ} rays differ by > 1 mm, of {judged} re-cast (float64, exact at edges) {with_us} agree with motorfactory, "
                  f"{with_them} with Open3D" + (
                      f"; agreement with the referee on every ray: motorfactory {1 - (differ - with_us) / len(rays):.6f}, "
                      f"Open3D {1 - (differ - with_them) / len(rays):.6f}" if judged == differ else ""))
            embree_p16 = None
            for mode in ["p16", "p1"] if embree_binary else []:
                e = embree_rate(mode)
                embree_p16 = embree_p16 or e["best_mrays"]
                theirs = np.load(f"{tmp}/embree.npy")
                agree = np.mean(np.isfinite(theirs[:, 0]) == np.isfinite(hits[:, 0]))
                print(f"  Embree 3 {mode}: {e['best_mrays']:.2f} Mrays/s (median {e['median_mrays']:.2f}), build {e['build_s']:.3f} s, "
                      f"{e['bvh_bytes_per_triangle']:.0f} bytes a triangle; motorfactory's packets {ours['best_mrays'] / e['best_mrays']:.2f}x; "
                      f"hit/miss agreement with motorfactory {agree:.5f}")
            rounds = [(ours["best_mrays"], best, embree_p16)]
            for _ in range(args.rounds - 1):
                rounds.append((ours_rate("packets")["best_mrays"],
                               open3d_rate(vertices, tris, rays, args.threads, args.repeats)[1],
                               embree_rate("p16")["best_mrays"] if embree_binary else None))
            line = lambda k: ", ".join(f"{r[k]:.2f}" for r in rounds)
            print(f"  {len(rounds)} rounds, best Mrays/s: motorfactory's packets {line(0)}; Open3D {line(1)}"
                  + (f"; Embree p16 {line(2)}" if embree_binary else "")
                  + f"; median ratio to Open3D {np.median([r[0] / r[1] for r in rounds]):.2f}x"
                  + (f", to Embree p16 {np.median([r[0] / r[2] for r in rounds]):.2f}x" if embree_binary else ""))


if __name__ == "__main__":
    main()
