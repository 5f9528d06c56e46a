# Scene construction and rendering helpers for the headless Blender tests (run inside Blender).
# Everything is generated here: no .blend files in git.
import math
import os
import sys

import bpy
import numpy as np
from mathutils import Vector

sys.path.insert(0, os.path.dirname(__file__))
import exr  # noqa: E402

WIDTH, HEIGHT = 64, 48


def check(cond, message):
    """Test assertion that also logs what passed (the test's output lists every check)."""
    if not cond:
        raise AssertionError(message)
    print("ok:", message, flush=True)


def args():
    """Arguments after `--` as a dict: --out DIR --build DIR ..."""
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    out = {}
    for i in range(0, len(argv) - 1, 2):
        out[argv[i].lstrip("-")] = argv[i + 1]
    return out


def clear():
    """Empties the current scene (keeps the scene and its view layers' settings)."""
    for coll in (bpy.data.objects, bpy.data.meshes, bpy.data.materials, bpy.data.lights,
                 bpy.data.cameras, bpy.data.images, bpy.data.curves, bpy.data.node_groups):
        for item in list(coll):
            if getattr(item, "type", None) in {'RENDER_RESULT', 'COMPOSITING'}:
                continue  # Blender's own render result images stay
            coll.remove(item)
    scene = bpy.context.scene
    for layer in list(scene.view_layers)[1:]:
        scene.view_layers.remove(layer)
    world = scene.world or bpy.data.worlds.new("World")
    scene.world = world
    world.use_nodes = False
    world.color = (0.0, 0.0, 0.0)
    r = scene.render
    r.resolution_x, r.resolution_y, r.resolution_percentage = WIDTH, HEIGHT, 100
    r.pixel_aspect_x = r.pixel_aspect_y = 1.0
    r.use_border = False
    r.film_transparent = False
    scene.use_nodes = False
    scene.frame_start = scene.frame_end = scene.frame_current = 1
    scene.view_settings.view_transform = 'Standard'
    scene.view_settings.look = 'None'
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    return scene


# --- Materials ---------------------------------------------------------------------------------

def _material(name):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    nt = m.node_tree
    for n in list(nt.nodes):
        nt.nodes.remove(n)
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    return m, nt, out


def shader_material(name, node_type, **inputs):
    m, nt, out = _material(name)
    node = nt.nodes.new(node_type)
    for key, value in inputs.items():
        if key in {"distribution"}:
            setattr(node, key, value)
        else:
            node.inputs[key].default_value = value
    nt.links.new(node.outputs[0], out.inputs["Surface"])
    return m


def feed(material, node_type, output, socket):
    """A new `node_type` node of `material` whose `output` feeds input `socket` of the material's
    shader (the node on its output's Surface); returns the new node."""
    nt = material.node_tree
    out = next(n for n in nt.nodes if n.type == 'OUTPUT_MATERIAL')
    shader = out.inputs["Surface"].links[0].from_node
    node = nt.nodes.new(node_type)
    nt.links.new(node.outputs[output], shader.inputs[socket])
    return node


def diffuse(name, color):
    return shader_material(name, "ShaderNodeBsdfDiffuse", Color=(*color, 1.0))


def glossy(name, roughness, color=(0.9, 0.9, 0.9)):
    """A Glossy BSDF with GGX (the distribution GDPT and the Cycles comparisons use)."""
    return shader_material(name, "ShaderNodeBsdfGlossy", Color=(*color, 1.0), Roughness=roughness,
                           distribution='GGX')


def emission(name, color, strength):
    return shader_material(name, "ShaderNodeEmission", Color=(*color, 1.0), Strength=strength)


def image_material(name, image):
    m, nt, out = _material(name)
    bsdf = nt.nodes.new("ShaderNodeBsdfDiffuse")
    tex = nt.nodes.new("ShaderNodeTexImage")
    tex.image = image
    nt.links.new(tex.outputs["Color"], bsdf.inputs["Color"])
    nt.links.new(bsdf.outputs[0], out.inputs["Surface"])
    return m


def normal_map_image(name, size=64, waves=3, tilt=0.6):
    """Non-colour float image of a wavy tangent-space normal field: x varies along u, y along v."""
    img = bpy.data.images.new(name, size, size, alpha=True, float_buffer=True)
    img.colorspace_settings.name = 'Non-Color'
    c = (np.arange(size) + 0.5) / size
    n = np.zeros((size, size, 3), np.float32)
    n[..., 0] = tilt * np.sin(2 * np.pi * waves * c)[None, :]
    n[..., 1] = tilt * np.cos(2 * np.pi * waves * c)[:, None]
    n[..., 2] = 1.0
    n /= np.linalg.norm(n, axis=2, keepdims=True)
    rgba = np.ones((size, size, 4), np.float32)
    rgba[..., :3] = 0.5 + 0.5 * n
    img.pixels.foreach_set(rgba.ravel())
    img.pack()
    return img


def normal_mapped(name, node_type, image, strength, **inputs):
    m = shader_material(name, node_type, **inputs)
    nt = m.node_tree
    bsdf = next(n for n in nt.nodes if n.bl_idname == node_type)
    nm = nt.nodes.new("ShaderNodeNormalMap")
    nm.inputs["Strength"].default_value = strength
    tex = nt.nodes.new("ShaderNodeTexImage")
    tex.image = image
    nt.links.new(tex.outputs["Color"], nm.inputs["Color"])
    nt.links.new(nm.outputs["Normal"], bsdf.inputs["Normal"])
    return m


# --- Objects -----------------------------------------------------------------------------------

def link(obj):
    bpy.context.scene.collection.objects.link(obj)
    return obj


def mesh_object(name, verts, faces, material=None, smooth=False, uvs=True):
    me = bpy.data.meshes.new(name)
    me.from_pydata(verts, [], faces)
    if uvs:
        layer = me.uv_layers.new(name="UVMap")
        # Planar UVs from x/y in the mesh's bounding box, so textures have a known placement.
        xs = [v[0] for v in verts]
        ys = [v[1] for v in verts]
        x0, y0 = min(xs), min(ys)
        sx, sy = (max(xs) - x0) or 1.0, (max(ys) - y0) or 1.0
        for loop in me.loops:
            v = verts[loop.vertex_index]
            layer.data[loop.index].uv = ((v[0] - x0) / sx, (v[1] - y0) / sy)
    for p in me.polygons:
        p.use_smooth = smooth
    if material is not None:
        me.materials.append(material)
    me.update()
    return link(bpy.data.objects.new(name, me))


def plane(name, size, location, rotation=(0, 0, 0), material=None):
    h = size / 2
    obj = mesh_object(name, [(-h, -h, 0), (h, -h, 0), (h, h, 0), (-h, h, 0)], [(0, 1, 2, 3)],
                      material)
    obj.location = location
    obj.rotation_euler = rotation
    return obj


def uv_sphere(name, radius, location, material=None, segments=48, rings=24):
    verts = []
    faces = []
    for i in range(rings + 1):
        theta = math.pi * i / rings
        for j in range(segments):
            phi = 2 * math.pi * j / segments
            verts.append((radius * math.sin(theta) * math.cos(phi),
                          radius * math.sin(theta) * math.sin(phi), radius * math.cos(theta)))
    for i in range(rings):
        for j in range(segments):
            a = i * segments + j
            b = i * segments + (j + 1) % segments
            faces.append((a, b, b + segments, a + segments))
    obj = mesh_object(name, verts, faces, material, smooth=True, uvs=False)
    obj.location = location
    return obj


def camera(location, target, lens=35.0, ortho_scale=None):
    cam = bpy.data.cameras.new("Camera")
    cam.lens = lens
    cam.sensor_fit = 'AUTO'
    if ortho_scale is not None:
        cam.type = 'ORTHO'
        cam.ortho_scale = ortho_scale
    obj = link(bpy.data.objects.new("Camera", cam))
    obj.location = location
    direction = Vector(target) - Vector(location)
    obj.rotation_euler = direction.to_track_quat('-Z', 'Y').to_euler()
    bpy.context.scene.camera = obj
    return obj


def light(kind, location, energy, target=None, color=(1, 1, 1), **props):
    data = bpy.data.lights.new(kind.lower(), kind)
    data.energy = energy
    data.color = color
    for k, v in props.items():
        setattr(data, k, v)
    obj = link(bpy.data.objects.new(kind.lower(), data))
    obj.location = location
    if target is not None:
        obj.rotation_euler = (Vector(target) - Vector(location)).to_track_quat('-Z', 'Y') \
            .to_euler()
    return obj


def room(size=4.0, color=(0.7, 0.7, 0.7), left=(0.7, 0.2, 0.2), right=(0.2, 0.6, 0.2)):
    """Open-front box around the origin, floor at z = 0 (a small Cornell box)."""
    h = size / 2
    white = diffuse("white", color)
    plane("floor", size, (0, 0, 0), material=white)
    plane("ceiling", size, (0, 0, size), (math.pi, 0, 0), white)
    plane("back", size, (0, h, h), (math.pi / 2, 0, 0), white)
    plane("left", size, (-h, 0, h), (0, math.pi / 2, 0), diffuse("red", left))
    plane("right", size, (h, 0, h), (0, -math.pi / 2, 0), diffuse("green", right))


# --- Rendering ---------------------------------------------------------------------------------

def setup_gdpt(scene, samples, mode='GPT', reconstruction='L2', bounces=4, seed=1):
    scene.render.engine = 'GDPT'
    g = scene.gdpt
    g.samples = samples
    g.mode = mode
    g.reconstruction = reconstruction
    g.max_bounces = g.diffuse_bounces = g.glossy_bounces = g.transmission_bounces = bounces
    g.seed = seed
    g.time_limit = 0.0
    g.alpha = 0.2
    g.pixel_filter_type = 'BOX'  # as setup_cycles()
    g.filter_width = 1.0
    g.blur_glossy = 0.0
    g.caustics_reflective = g.caustics_refractive = True


def setup_cycles(scene, samples, bounces=4, seed=1):
    scene.render.engine = 'CYCLES'
    c = scene.cycles
    c.device = 'CPU'
    c.samples = samples
    c.use_adaptive_sampling = False
    c.use_denoising = False
    c.max_bounces = c.diffuse_bounces = c.glossy_bounces = bounces
    c.transmission_bounces = c.transparent_max_bounces = bounces
    c.volume_bounces = 0
    c.sample_clamp_direct = c.sample_clamp_indirect = 0.0
    c.blur_glossy = 0.0
    c.caustics_reflective = c.caustics_refractive = True
    c.light_sampling_threshold = 0.0
    c.pixel_filter_type = 'BOX'
    c.filter_width = 1.0
    c.seed = seed
    c.min_light_bounces = 0
    c.min_transparent_bounces = 0
    scene.render.use_persistent_data = False


def render_engine(scene, name, engine, samples, **gdpt_settings):
    """Renders `name`.exr (multilayer) in the test's output folder with GDPT (setup_gdpt with
    `gdpt_settings`, and checks that Gradient PT really rendered) or Cycles; returns the path."""
    import gdpt.engine as engine_module
    if engine == 'GDPT':
        setup_gdpt(scene, samples, **gdpt_settings)
        engine_module.LAST_RENDER.clear()
    else:
        setup_cycles(scene, samples)
    path = render(scene, os.path.join(args()["out"], name + ".exr"), multilayer=True)
    if engine == 'GDPT':
        check(engine_module.LAST_RENDER.get("status") == "finished", f"Gradient PT rendered {name}")
    return path


def reconstruct_tree(scene, norm='L1', alpha=0.2):
    """Compositor: Render Layers (Primal, Gradients, Emission) -> Gradient Reconstruct -> Composite
    (the engine must be GDPT for the Render Layers node to show its passes). Returns the node."""
    scene.use_nodes = True
    tree = scene.node_tree
    for n in list(tree.nodes):
        tree.nodes.remove(n)
    rl = tree.nodes.new("CompositorNodeRLayers")
    node = tree.nodes.new("CompositorNodeGDPTReconstruct")
    node.norm, node.alpha = norm, alpha
    comp = tree.nodes.new("CompositorNodeComposite")
    for k in ("Primal", "Gradient X", "Gradient Y", "Emission"):
        tree.links.new(rl.outputs[k], node.inputs[k])
    tree.links.new(node.outputs["Image"], comp.inputs["Image"])
    return node


def render(scene, path, multilayer=False):
    """Renders the current frame to `path` (.exr) like `-f`, returns the path."""
    s = scene.render.image_settings
    s.file_format = 'OPEN_EXR_MULTILAYER' if multilayer else 'OPEN_EXR'
    s.color_depth = '32'
    s.exr_codec = 'ZIP'
    s.color_mode = 'RGBA'
    scene.render.use_file_extension = False
    scene.render.filepath = path
    if os.path.exists(path):
        os.remove(path)
    bpy.ops.render.render(write_still=True)
    if not os.path.exists(path):
        raise RuntimeError(f"render did not write {path}")
    return path


def read_rgb(path, prefix=""):
    return exr.rgb(exr.read_exr(path), prefix)


def rel_mse(a, b, eps=1e-2):
    """Relative MSE of image a against reference b (mean over pixels and channels)."""
    import numpy as np
    return float(np.mean((a - b) ** 2 / (b ** 2 + eps)))
