"""Renders the appearance reference images with Cycles (pip bpy 5.0.1), from scenes.json.

Usage, in the add-on oracle's venv (see ../../../shared/reference/addon-oracle/README.md):
    python reference.py [SCENE ...]            # every scene when none is named

Writes reference/<scene>.png (8-bit sRGB, Blender's Standard view transform) and, for scenes with
parts, reference/<scene>-parts.png (8-bit grey: 20 x the part's number, 0 for none) next to this
file. Each scene holds a camera, lights in Blender's units, and either analytic shapes (tessellated
exactly as motorfactory's sensor::shapes does) or a motor built by the MotorFactory add-on with
its colour render on, each part's material taken from the add-on's own table (Materia_Tables) and
set on the Principled BSDF by input name (the add-on sets the viewport values, which Cycles in
Blender 5 ignores). Faces the add-on leaves without a material take their part's own.
"""
import collections
import json
import math
import os
import random
import sys
import tempfile
import warnings

import bpy
from mathutils import Matrix, Vector

warnings.simplefilter('ignore', DeprecationWarning)  # use_nodes, still needed in bpy 5.0

HERE = os.path.dirname(os.path.abspath(__file__))
ORACLE = os.path.join(HERE, '..', '..', '..', 'shared', 'reference', 'addon-oracle')
# the add-on's objects grouped as the comparison's parts, by name prefix
ADDON_PARTS = {
    'Bolt_': 'bolts', 'Motor': 'pole pot', 'Charger': 'electric connection',
    'Gear_Container': 'gear container', 'Cover': 'cover', 'Magnet': 'magnets', 'Rotor': 'armature',
    'Lower_Inner_Gear': 'gears', 'Upper_Inner_Gear': 'gears', 'Inner_Gear': 'gears',
}


def clear():
    for collection in (bpy.data.objects, bpy.data.meshes, bpy.data.materials, bpy.data.lights,
                       bpy.data.cameras, bpy.data.worlds):
        for item in list(collection):
            collection.remove(item)


def principled(m, spec):
    mat = bpy.data.materials.new('m')
    mat.use_nodes = True
    p = mat.node_tree.nodes['Principled BSDF']
    p.inputs['Base Color'].default_value = (*spec['colour'], 1.0)
    p.inputs['Metallic'].default_value = spec['metallic']
    p.inputs['Roughness'].default_value = spec['roughness']
    p.inputs['Specular IOR Level'].default_value = spec['ior_level']
    p.inputs['IOR'].default_value = 1.5
    m.data.materials.append(mat)


def mesh(name, triangles):
    verts, faces = [], []
    for t in triangles:
        faces.append((len(verts), len(verts) + 1, len(verts) + 2))
        verts.extend(t)
    data = bpy.data.meshes.new(name)
    data.from_pydata(verts, [], faces)
    obj = bpy.data.objects.new(name, data)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def grid(n, p):
    tris = []
    for i in range(n):
        for j in range(n):
            tris.append((p(i, j), p(i + 1, j), p(i + 1, j + 1)))
            tris.append((p(i, j), p(i + 1, j + 1), p(i, j + 1)))
    return tris


def sphere(c, r, n):
    def p(i, j):
        th, ph = math.pi * i / n, 2 * math.pi * j / n
        return (c[0] + r * math.sin(th) * math.cos(ph), c[1] + r * math.sin(th) * math.sin(ph),
                c[2] + r * math.cos(th))
    return grid(n, p)


def rect(c, a, b):
    c, a, b = Vector(c), Vector(a), Vector(b)
    k = [c - a - b, c + a - b, c + a + b, c - a + b]
    return [tuple(map(tuple, (k[0], k[1], k[2]))), tuple(map(tuple, (k[0], k[2], k[3])))]


def create_corrosion(self, obj, texture, corr_percent, part):
    """The add-on's create_corrosion (utility.py), node for node and value for value, with the
    inputs it numbers as Blender 2.90 did addressed by name: two Principled BSDFs, the part's and
    a metallic one (roughness 0.774) coloured by the rust image, mixed by the mask texture
    coordinate (object) -> noise (scale 0.5, detail 16, roughness 0.833) -> ramp (black at
    percent / 250-400, white at 0.909) -> Voronoi (scale 2) colour -> ramp (white at 0.723,
    black at 0.805). The bump node it wires at strength 0 is left out."""
    mat = bpy.data.materials.new(name='Corrosion')
    mat.use_nodes = True
    obj.data.materials.append(mat)
    obj.active_material = mat
    nodes, link = mat.node_tree.nodes, mat.node_tree.links.new
    p1, out = nodes['Principled BSDF'], nodes['Material Output']
    table = self.Materia_Tables[part]
    p1.inputs['Base Color'].default_value = table['diffuse_color']
    p1.inputs['Metallic'].default_value = table['metallic']
    p1.inputs['Roughness'].default_value = table['roughness']
    p1.inputs['Specular IOR Level'].default_value = table['specular_intensity']
    mix = nodes.new('ShaderNodeMixShader')
    p2 = nodes.new('ShaderNodeBsdfPrincipled')
    p2.inputs['Metallic'].default_value = 1
    p2.inputs['Specular IOR Level'].default_value = 0.5
    p2.inputs['Roughness'].default_value = 0.774
    ramp1 = nodes.new('ShaderNodeValToRGB')
    ramp1.name = 'mask'
    ramp1.color_ramp.elements[1].position = 0.723
    ramp1.color_ramp.elements[0].position = 0.805
    voronoi = nodes.new('ShaderNodeTexVoronoi')
    voronoi.inputs['Scale'].default_value = 2
    ramp2 = nodes.new('ShaderNodeValToRGB')
    ramp2.color_ramp.elements[1].position = 0.909
    noise = nodes.new('ShaderNodeTexNoise')
    noise.inputs['Scale'].default_value = 0.5
    noise.inputs['Detail'].default_value = 16
    noise.inputs['Roughness'].default_value = 0.833
    mapping = nodes.new('ShaderNodeMapping')
    coords = nodes.new('ShaderNodeTexCoord')
    image = nodes.new('ShaderNodeTexImage')
    image.image = bpy.data.images.load(self.Path_corrosion[texture])
    link(mix.outputs[0], out.inputs['Surface'])
    link(ramp1.outputs['Color'], mix.inputs['Fac'])
    link(p1.outputs[0], mix.inputs[1])
    link(p2.outputs[0], mix.inputs[2])
    link(voronoi.outputs['Color'], ramp1.inputs['Fac'])
    link(ramp2.outputs['Color'], voronoi.inputs['Vector'])
    link(noise.outputs['Color'], ramp2.inputs['Fac'])
    link(mapping.outputs['Vector'], noise.inputs['Vector'])
    link(coords.outputs['Object'], mapping.inputs['Vector'])
    link(image.outputs['Color'], p2.inputs['Base Color'])
    if corr_percent < 50:
        num = random.randrange(250, 280, 1)
    elif 50 <= corr_percent <= 95:
        num = random.randrange(300, 400, 1)
    else:
        num = random.randrange(280, 300, 1)
    ramp2.color_ramp.elements[0].position = corr_percent / num
    return mat


def rust(o, wear, units):
    """Rusts object `o` as motorfactory's coverage mask does, every node Blender's own: the
    texture coordinates of an empty at the object's centre scaled to `units` per metre, a noise
    (scale 0.5, detail 3, roughness 0.5) below wear['threshold'] (sensor::wear's quantile of
    the share, with an edge 0.02 wide) mixing the object's material with the add-on's rust BSDF
    (metallic 1, roughness 0.774) coloured by wear['colour'] times 1 + spread / 0.08 x (a
    noise at scale 2, detail 3, roughness 0.6, less 1/2)."""
    lo = Vector(o.bound_box[0])
    hi = Vector(o.bound_box[6])
    frame = bpy.data.objects.new('frame_' + o.name, None)
    bpy.context.scene.collection.objects.link(frame)
    frame.location = o.matrix_world @ ((lo + hi) / 2)
    frame.scale = (1 / units,) * 3
    for k, clean in enumerate(o.data.materials):
        mat = clean.copy()
        nodes, link = mat.node_tree.nodes, mat.node_tree.links.new
        out = nodes['Material Output']
        part = out.inputs['Surface'].links[0].from_socket
        coords = nodes.new('ShaderNodeTexCoord')
        coords.object = frame

        def noise(scale, detail, roughness):
            n = nodes.new('ShaderNodeTexNoise')
            for key, value in (('Scale', scale), ('Detail', detail), ('Roughness', roughness)):
                n.inputs[key].default_value = value
            link(coords.outputs['Object'], n.inputs['Vector'])
            return n.outputs['Fac']

        def math(op, a, b, clamp=False):
            m = nodes.new('ShaderNodeMath')
            m.operation, m.use_clamp = op, clamp
            for socket, value in zip(m.inputs, (a, b)):
                if isinstance(value, float):
                    socket.default_value = value
                else:
                    link(value, socket)
            return m.outputs[0]

        mask = math('ADD', math('DIVIDE', math('SUBTRACT', wear['threshold'], noise(0.5, 3, 0.5)),
                                0.02), 0.5, clamp=True)
        shade = math('MAXIMUM', math('ADD', math('MULTIPLY', math('SUBTRACT', noise(2.0, 3, 0.6),
                                                                   0.5), wear['spread'] / 0.08),
                                     1.0), 0.0)
        colour = nodes.new('ShaderNodeMix')
        colour.data_type, colour.blend_type = 'RGBA', 'MULTIPLY'
        colour.inputs['Factor'].default_value = 1.0
        colour.inputs[6].default_value = (*wear['colour'], 1.0)
        link(shade, colour.inputs[7])
        bsdf = nodes.new('ShaderNodeBsdfPrincipled')
        bsdf.inputs['Metallic'].default_value = 1.0
        bsdf.inputs['Roughness'].default_value = 0.774
        bsdf.inputs['Specular IOR Level'].default_value = 0.5
        bsdf.inputs['IOR'].default_value = 1.5
        link(colour.outputs[2], bsdf.inputs['Base Color'])
        mix = nodes.new('ShaderNodeMixShader')
        link(mask, mix.inputs['Fac'])
        link(part, mix.inputs[1])
        link(bsdf.outputs[0], mix.inputs[2])
        link(mix.outputs[0], out.inputs['Surface'])
        o.data.materials[k] = mat


def motor(case, corrosion=None):
    """The add-on's motor of `case` (cases.json) with its colour render on, in metres, and its
    corrosion (type and percent on the bolts and on the pole pot) or none; returns each mesh
    object with its part group."""
    sys.path.insert(0, os.path.join(ORACLE, 'addon'))
    import add_mesh_BoltFactory
    import motor_factory
    from motor_factory import utility
    utility.Factory.create_corrosion = create_corrosion
    if not hasattr(bpy.ops.mesh, 'add_motor') or not hasattr(bpy.types, 'MESH_OT_add_motor'):
        add_mesh_BoltFactory.register()
        motor_factory.register()
    params = json.load(open(os.path.join(ORACLE, 'cases.json')))[case]
    params = {k: v for k, v in params.items() if k not in ('save_path', 'temp_save', 'test')}
    corrosion = corrosion or {}
    params.update(mf_Color_Render=True, mf_Combine=False,
                  mf_corrosion_Type_Bolt=corrosion.get('bolt_type', 'Rust 1'),
                  mf_corrosion_Percent_Bolt=corrosion.get('bolt_percent', 0.0),
                  mf_corrosion_Type_Bottom=corrosion.get('pole_pot_type', 'Rust 1'),
                  mf_corrosion_Percent_Bottom=corrosion.get('pole_pot_percent', 0.0))
    os.environ.setdefault('MF_BOOL_SOLVER', 'FAST')
    save = tempfile.mkdtemp() + '/'
    random.seed(0)
    assert 'FINISHED' in bpy.ops.mesh.add_motor(**params, save_path=save, temp_save=False)
    parts = []
    for o in bpy.data.objects:
        if o.type != 'MESH':
            continue
        group = next((g for k, g in ADDON_PARTS.items() if o.name.startswith(k)), None)
        if group is None:
            o.hide_render = True
            continue
        # faces the add-on leaves without a material (most of the type B cover, bits of the
        # type A cover and gear container: parts it joined before colouring) would render in
        # Blender's default grey; they take the part's own table material, as the add-on means
        used = collections.Counter(p.material_index for p in o.data.polygons
                                   if o.data.materials[p.material_index] is not None)
        if used:
            own = o.data.materials[used.most_common(1)[0][0]]
            for k, mat in enumerate(o.data.materials):
                if mat is None:
                    o.data.materials[k] = own
        # the add-on sets its table on the material's viewport values; Cycles reads the node
        for mat in o.data.materials:
            if mat is None or mat.name.startswith('Corrosion'):
                continue
            p = mat.node_tree.nodes['Principled BSDF']
            p.inputs['Base Color'].default_value = tuple(mat.diffuse_color)
            p.inputs['Metallic'].default_value = mat.metallic
            p.inputs['Roughness'].default_value = mat.roughness
            p.inputs['Specular IOR Level'].default_value = mat.specular_intensity
            p.inputs['IOR'].default_value = 1.5
        o.matrix_world = Matrix.Scale(0.01, 4) @ o.matrix_world
        parts.append((o, group))
    return parts


def camera(spec):
    eye, target, up = (Vector(spec[k]) for k in ('eye', 'target', 'up'))
    forward = (target - eye).normalized()
    right = forward.cross(up).normalized()
    down = forward.cross(right)
    cam = bpy.data.objects.new('camera', bpy.data.cameras.new('camera'))
    bpy.context.scene.collection.objects.link(cam)
    # Blender's camera looks along its -z with +y up
    m = Matrix((right, -down, -forward)).transposed().to_4x4()
    m.translation = eye
    cam.matrix_world = m
    cam.data.sensor_fit = 'HORIZONTAL'
    cam.data.angle_x = math.radians(spec['hfov_deg'])
    cam.data.clip_start = 1e-3
    bpy.context.scene.camera = cam
    scene = bpy.context.scene
    scene.render.resolution_x, scene.render.resolution_y = spec['width'], spec['height']
    scene.render.resolution_percentage = 100


def lights(spec):
    for k, light in enumerate(spec['lights']):
        colour = light.get('colour', [1.0, 1.0, 1.0])
        if light['type'] == 'point':
            data = bpy.data.lights.new('light%d' % k, 'POINT')
            data.shadow_soft_size = 0.0
            data.use_soft_falloff = False
            m = Matrix.Translation(light['position'])
        else:
            data = bpy.data.lights.new('light%d' % k, 'AREA')
            u, v = Vector(light['half_u']), Vector(light['half_v'])
            data.shape = 'RECTANGLE'
            data.size, data.size_y = 2 * v.length, 2 * u.length
            # local x along v, y along u: the light's -z (where it shines) is u x v
            x, y = v.normalized(), u.normalized()
            m = Matrix((x, y, x.cross(y))).transposed().to_4x4()
            m.translation = light['centre']
        data.energy = light['power']
        data.color = colour
        obj = bpy.data.objects.new('light%d' % k, data)
        obj.matrix_world = m
        bpy.context.scene.collection.objects.link(obj)
    world = bpy.data.worlds.new('world')
    world.use_nodes = True
    bg = world.node_tree.nodes['Background']
    bg.inputs['Color'].default_value = (*spec['environment'], 1.0)
    bg.inputs['Strength'].default_value = 1.0
    bpy.context.scene.world = world


def settings(samples, width=1.0):
    s = bpy.context.scene
    s.render.engine = 'CYCLES'
    c = s.cycles
    c.device = 'CPU'
    c.samples = samples
    c.use_adaptive_sampling = False
    c.use_denoising = False
    c.seed = 0
    c.max_bounces = 4
    c.diffuse_bounces = c.glossy_bounces = 4
    c.transmission_bounces = c.volume_bounces = c.transparent_max_bounces = 0
    c.blur_glossy = 0.0
    c.sample_clamp_direct = c.sample_clamp_indirect = 0.0
    c.pixel_filter_type = 'BOX'
    c.filter_width = width
    s.view_settings.view_transform = 'Standard'
    s.view_settings.look = 'None'
    s.view_settings.exposure = 0.0
    s.view_settings.gamma = 1.0
    s.render.film_transparent = False
    s.render.dither_intensity = 0.0
    s.render.image_settings.file_format = 'PNG'
    s.render.image_settings.color_mode = 'RGB'
    s.render.image_settings.color_depth = '8'


def render(path):
    bpy.context.scene.render.filepath = path
    bpy.ops.render.render(write_still=True)


def parts_pass(objects, names, path):
    """Each object's part number × 20 as an emission, one sample at each pixel's centre."""
    for o, name in objects:
        mat = bpy.data.materials.new('part')
        mat.use_nodes = True
        nodes = mat.node_tree.nodes
        nodes.remove(nodes['Principled BSDF'])
        e = nodes.new('ShaderNodeEmission')
        value = 0.0 if name is None else 20 * (names.index(name) + 1) / 255
        e.inputs['Color'].default_value = (value, value, value, 1)
        mat.node_tree.links.new(e.outputs[0], nodes['Material Output'].inputs[0])
        o.data.materials.clear()
        o.data.materials.append(mat)
    bpy.context.scene.world.node_tree.nodes['Background'].inputs['Strength'].default_value = 0
    for o in bpy.data.objects:
        if o.type == 'LIGHT':
            o.hide_render = True
    settings(1, width=0.01)
    bpy.context.scene.view_settings.view_transform = 'Raw'
    bpy.context.scene.render.image_settings.color_mode = 'BW'
    render(path)


def patterns(spec, out):
    """The add-on's corrosion mask and its stages on a plane z = 0 seen from above by an
    orthographic camera, one sample at each pixel's centre, as 16-bit PNGs of the raw values:
    out-noise.png (the colour of the mask's noise at 3 octaves), out-cells.png (the Voronoi's colour of the object
    coordinates), out-voronoi.png (the Voronoi's colour of the ramped
    noise) and out-mask.png (the mask), each pixel's centre at world (x, y) =
    (x0 + (i + 1/2) s, y0 - (j + 1/2) s)."""
    n, (x0, y0), size = spec['pixels'], spec['corner'], spec['size']
    o = mesh('plane', rect((x0 + size / 2, y0 - size / 2, 0), (size / 2 + 1, 0, 0),
                           (0, size / 2 + 1, 0)))
    obj = type('Factory', (), {'Materia_Tables': {'Bit': {
        'diffuse_color': (0.9, 0.9, 0.9, 1), 'metallic': 0.9, 'roughness': 0.1,
        'specular_intensity': 0.7}}, 'Path_corrosion': {'Rust 1': os.path.join(
            ORACLE, 'addon', 'motor_factory', 'materials', 'rust1.jpg')}})()
    random.seed(0)
    mat = create_corrosion(obj, o, 'Rust 1', spec['percent'], 'Bit')
    nodes, link = mat.node_tree.nodes, mat.node_tree.links.new
    print('threshold', nodes['Color Ramp'].color_ramp.elements[0].position)
    cam = bpy.data.objects.new('camera', bpy.data.cameras.new('camera'))
    bpy.context.scene.collection.objects.link(cam)
    cam.data.type = 'ORTHO'
    cam.data.ortho_scale = size
    cam.location = (x0 + size / 2, y0 - size / 2, 5)
    bpy.context.scene.camera = cam
    scene = bpy.context.scene
    scene.render.resolution_x = scene.render.resolution_y = n
    scene.render.resolution_percentage = 100
    settings(1, width=0.01)
    scene.view_settings.view_transform = 'Raw'
    scene.render.image_settings.color_depth = '16'
    emission = nodes.new('ShaderNodeEmission')
    link(emission.outputs[0], nodes['Material Output'].inputs['Surface'])
    cells = nodes.new('ShaderNodeTexVoronoi')
    cells.name = 'cells'
    cells.inputs['Scale'].default_value = 2
    link(nodes['Texture Coordinate'].outputs['Object'], cells.inputs['Vector'])
    # the mask's noise at 3 octaves: its 16 would differ at the 1/200 pixel by which a sample
    # may miss the pixel's centre
    octaves = nodes.new('ShaderNodeTexNoise')
    octaves.name = 'octaves'
    for key, value in (('Scale', 0.5), ('Detail', 2), ('Roughness', 0.833)):
        octaves.inputs[key].default_value = value
    link(nodes['Texture Coordinate'].outputs['Object'], octaves.inputs['Vector'])
    for name, node in (('noise', 'octaves'), ('cells', 'cells'),
                       ('voronoi', 'Voronoi Texture'), ('mask', 'mask')):
        link(nodes[node].outputs['Color'], emission.inputs['Color'])
        render('%s-%s.png' % (out, name))


def main():
    scenes = json.load(open(os.path.join(HERE, 'scenes.json')))
    names = sys.argv[1:] or list(scenes)
    for name in names:
        spec = scenes[name]
        clear()
        if 'pattern' in spec:
            patterns(spec['pattern'], os.path.join(HERE, 'reference', name))
            continue
        objects = []
        if 'motor' in spec:
            objects = motor(spec['motor']['case'], spec['motor'].get('corrosion'))
            wear = spec['motor'].get('wear')
            for o, group in objects if wear else []:
                if group in wear['parts']:
                    rust(o, wear, 1000.0 if group == 'bolts' else 100.0)
        for k, obj in enumerate(spec.get('objects', [])):
            if obj['shape'] == 'sphere':
                tris = sphere(obj['centre'], obj['radius'], obj['n'])
            else:
                tris = rect(obj['centre'], obj['half_u'], obj['half_v'])
            o = mesh('object%d' % k, tris)
            principled(o, obj['material'])
            part = obj.get('part')
            objects.append((o, None if part is None else spec['parts'][part - 1]))
        camera(spec['camera'])
        lights(spec['lighting'])
        settings(spec['cycles_samples'] if 'cycles_samples' in spec else 4 * spec['samples'])
        out = os.path.join(HERE, 'reference', name)
        render(out + '.png')
        if 'parts' in spec:
            parts_pass(objects, spec['parts'], out + '-parts.png')
        print('%s: written' % name)


if __name__ == '__main__':
    main()
