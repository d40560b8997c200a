"""Renders a scene written by `cargo run --release -p scene --example cycles_scene` with Cycles
(pip bpy 5.0.1) as BlenderProc renders by default, timed: adaptive sampling to a noise threshold
of 0.01 with at most 1024 samples, Intel's OpenImageDenoise, 3 bounces; Blender's Standard view
transform at the scene's exposure. Then the SSIM between it and this renderer's frames.

Usage, in a venv with bpy 5.0.1, numpy and Pillow:
    python render_cycles.py OUT_DIR [THREADS]

Writes OUT_DIR/cycles.png and prints the render's time and the SSIMs (luminance, 7x7 windows,
as scikit-image's defaults).
"""
import json
import math
import os
import sys
import time

import bpy
import addon_utils  # noqa: E402  (bpy's own module, importable once bpy is)
import numpy as np
from mathutils import Matrix

# Cycles is an add-on of bpy's: enabled before this folder's neighbours join the path
addon_utils.enable('cycles', default_set=True)
HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, '..', 'appearance'))
import reference  # noqa: E402  (its lights and clearing)


def build(doc):
    reference.clear()
    for o in doc['objects']:
        p = o['positions']
        verts = [(p[i], p[i + 1], p[i + 2]) for i in range(0, len(p), 3)]
        t = o['triangles']
        faces = [(t[i], t[i + 1], t[i + 2]) for i in range(0, len(t), 3)]
        data = bpy.data.meshes.new(o['name'])
        data.from_pydata(verts, [], faces)
        obj = bpy.data.objects.new(o['name'], data)
        bpy.context.scene.collection.objects.link(obj)
        reference.principled(obj, o['material'])
    c = doc['camera']
    cam = bpy.data.objects.new('camera', bpy.data.cameras.new('camera'))
    bpy.context.scene.collection.objects.link(cam)
    # OpenCV's camera (x right, y down, z forward) to Blender's (-z forward, y up)
    m = Matrix(c['camera_to_world']) @ Matrix.Diagonal((1, -1, -1, 1))
    cam.matrix_world = m
    w, h = c['width'], c['height']
    cam.data.sensor_fit = 'HORIZONTAL'
    cam.data.angle_x = 2 * math.atan(w / 2 / c['fx'])
    cam.data.shift_x = -(c['cx'] - (w - 1) / 2) / max(w, h)
    cam.data.shift_y = (c['cy'] - (h - 1) / 2) / max(w, h)
    cam.data.clip_start = 1e-3
    scene = bpy.context.scene
    scene.camera = cam
    scene.render.resolution_x, scene.render.resolution_y = w, h
    scene.render.resolution_percentage = 100
    reference.lights(doc['lighting'])


def blenderproc_settings(exposure, threads):
    reference.settings(1024)
    s = bpy.context.scene
    c = s.cycles
    c.use_adaptive_sampling = True
    c.adaptive_threshold = 0.01
    c.use_denoising = True
    c.denoiser = 'OPENIMAGEDENOISE'
    c.max_bounces = 3
    c.diffuse_bounces = c.glossy_bounces = 3
    c.pixel_filter_type = 'BLACKMAN_HARRIS'
    c.filter_width = 1.5
    s.view_settings.exposure = math.log2(exposure)
    if threads:
        s.render.threads_mode = 'FIXED'
        s.render.threads = threads


def grey(path):
    from PIL import Image
    rgb = np.asarray(Image.open(path).convert('RGB'), dtype=np.float64) / 255
    return rgb @ np.array([0.2126, 0.7152, 0.0722])


def ssim(a, b, win=7):
    def mean(x):
        c = np.cumsum(np.cumsum(np.pad(x, ((1, 0), (1, 0))), 0), 1)
        s = c[win:, win:] - c[:-win, win:] - c[win:, :-win] + c[:-win, :-win]
        return s / win ** 2
    c1, c2 = 0.01 ** 2, 0.03 ** 2
    ma, mb = mean(a), mean(b)
    n = win ** 2
    va = (mean(a * a) - ma ** 2) * n / (n - 1)
    vb = (mean(b * b) - mb ** 2) * n / (n - 1)
    cov = (mean(a * b) - ma * mb) * n / (n - 1)
    s = ((2 * ma * mb + c1) * (2 * cov + c2)) / ((ma ** 2 + mb ** 2 + c1) * (va + vb + c2))
    return float(s.mean())


def main():
    out = sys.argv[1]
    threads = int(sys.argv[2]) if len(sys.argv) > 2 else 0
    doc = json.load(open(os.path.join(out, 'scene.json')))
    build(doc)
    blenderproc_settings(doc['exposure'], threads)
    path = os.path.join(out, 'cycles.png')
    t = time.time()
    reference.render(path)
    seconds = time.time() - t
    print('cycles: %.1f s' % seconds, flush=True)
    cycles = grey(path)
    for name in ('ours.png', 'ours-converged.png'):
        print('SSIM %s vs cycles: %.3f' % (name, ssim(grey(os.path.join(out, name)), cycles)))


if __name__ == '__main__':
    main()
