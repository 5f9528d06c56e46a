# The benchmark report's scenes (bench/report), built in Blender from scratch: no .blend in git.
# Each builder fills the cleared current scene; SCENES lists them in report order.
#   blender -b --factory-startup --python bench/scenes/build.py -- NAME OUT.blend [WxH]
import math
import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tests",
                                "blender"))
import scenes as S  # noqa: E402


def box(name, size, location, material, rotation_z=0.0):
    """An axis-aligned box (closed, outward faces) of `size` (x, y, z) resting on `location`."""
    x, y, z = (s / 2 for s in size)
    verts = [(-x, -y, 0), (x, -y, 0), (x, y, 0), (-x, y, 0),
             (-x, -y, 2 * z), (x, -y, 2 * z), (x, y, 2 * z), (-x, y, 2 * z)]
    faces = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
    obj = S.mesh_object(name, verts, faces, material)
    obj.location = location
    obj.rotation_euler = (0, 0, rotation_z)
    return obj


def glass(name, roughness=0.0, ior=1.45):
    return S.shader_material(name, "ShaderNodeBsdfGlass", Roughness=roughness, IOR=ior)


def cornell_panel(scene):
    """Diffuse Cornell box lit by an emissive mesh panel a hair below the ceiling."""
    S.room()
    S.plane("panel", 1.0, (0, 0, 3.995), (math.pi, 0, 0), S.emission("panel", (1, 0.9, 0.75), 12))
    box("tall", (0.9, 0.9, 1.8), (-0.7, 0.6, 0), S.diffuse("box_a", (0.75, 0.75, 0.75)), 0.3)
    box("short", (0.9, 0.9, 0.9), (0.8, -0.3, 0), S.diffuse("box_b", (0.75, 0.75, 0.75)), -0.3)
    S.camera((0, -5.5, 2.0), (0, 0, 1.9), lens=30)


def _walls_with_window(width, depth, height, white):
    """A closed room, x in [-w/2, w/2], y in [-d/2, d/2], z in [0, h], with a window hole in the
    +y wall between x in [-1, 1] and z in [0.9, 2.1]."""
    w, d, h = width / 2, depth / 2, height
    S.plane("floor", 1, (0, 0, 0), material=white).scale = (width, depth, 1)
    S.plane("ceiling", 1, (0, 0, h), (math.pi, 0, 0), white).scale = (width, depth, 1)
    S.plane("back", 1, (0, -d, h / 2), (-math.pi / 2, 0, 0), white).scale = (width, h, 1)
    S.plane("left", 1, (-w, 0, h / 2), (0, math.pi / 2, 0), white).scale = (h, depth, 1)
    S.plane("right", 1, (w, 0, h / 2), (0, -math.pi / 2, 0), white).scale = (h, depth, 1)
    # The window wall: four pieces around the hole, facing into the room (-y).
    for name, x0, x1, z0, z1 in (("win_l", -w, -1, 0, h), ("win_r", 1, w, 0, h),
                                 ("win_b", -1, 1, 0, 0.9), ("win_t", -1, 1, 2.1, h)):
        piece = S.plane(name, 1, ((x0 + x1) / 2, d, (z0 + z1) / 2), (math.pi / 2, 0, 0), white)
        piece.scale = (x1 - x0, z1 - z0, 1)


def interior(scene):
    """A furnished room lit only by the world through one window: indirect light, textures,
    a mirror."""
    white = S.diffuse("wall", (0.75, 0.73, 0.7))
    _walls_with_window(6.0, 5.0, 3.0, white)
    grid = bpy.data.images.new("floor_grid", 512, 512)
    grid.generated_type = 'COLOR_GRID'
    floor = bpy.data.objects["floor"]
    floor.data.materials.clear()
    floor.data.materials.append(S.image_material("parquet", grid))
    painting = bpy.data.images.new("painting", 256, 256)
    painting.generated_type = 'UV_GRID'
    S.plane("painting", 1, (-2.98, 0.2, 1.6), (0, math.pi / 2, 0),
            S.image_material("painting", painting)).scale = (0.9, 1.3, 1)
    S.plane("mirror", 1, (2.98, -0.6, 1.5), (0, -math.pi / 2, 0),
            S.glossy("mirror", 0.0, (0.95, 0.95, 0.95))).scale = (1.4, 1.2, 1)
    wood = S.diffuse("wood", (0.45, 0.28, 0.15))
    box("table_top", (1.6, 0.9, 0.06), (0.2, 0.4, 0.72), wood)
    for i, (x, y) in enumerate(((-0.5, 0.05), (0.9, 0.05), (-0.5, 0.75), (0.9, 0.75))):
        box(f"leg{i}", (0.06, 0.06, 0.72), (x, y, 0), wood)
    fabric = S.diffuse("fabric", (0.2, 0.3, 0.55))
    box("sofa_seat", (2.2, 0.9, 0.45), (-0.6, -1.9, 0), fabric)
    box("sofa_back", (2.2, 0.25, 0.5), (-0.6, -2.25, 0.45), fabric)
    S.uv_sphere("vase", 0.18, (0.5, 0.4, 0.96), S.glossy("vase", 0.15, (0.8, 0.3, 0.2)))
    scene.world.color = (2.2, 2.4, 2.8)
    S.camera((-2.3, -2.0, 1.5), (0.6, 1.2, 1.1), lens=22)


def glossy(scene):
    """GGX metals at roughness 0.05, 0.2 and 0.5 under an area light."""
    S.plane("floor", 12, (0, 0, 0), material=S.diffuse("floor", (0.5, 0.5, 0.5)))
    S.plane("back", 12, (0, 3, 3), (math.pi / 2, 0, 0), S.diffuse("back", (0.4, 0.45, 0.5)))
    for x, r, color in ((-1.5, 0.05, (0.95, 0.75, 0.35)), (0, 0.2, (0.95, 0.6, 0.5)),
                        (1.5, 0.5, (0.9, 0.9, 0.92))):
        S.uv_sphere(f"metal_{r}", 0.65, (x, 0.5, 0.65), S.glossy(f"metal_{r}", r, color))
    S.light('AREA', (0.5, -1.5, 3.5), 300.0, target=(0, 0.5, 0.5), size=1.2)
    scene.world.color = (0.02, 0.02, 0.025)
    S.camera((0, -5.0, 2.0), (0, 0.5, 0.6), lens=40)


def glass_caustics(scene):
    """A smooth glass sphere and a mirror on a diffuse floor, a small light: caustics."""
    S.plane("floor", 12, (0, 0, 0), material=S.diffuse("floor", (0.7, 0.7, 0.7)))
    S.plane("back", 12, (0, 3, 3), (math.pi / 2, 0, 0), S.diffuse("back", (0.6, 0.6, 0.55)))
    S.uv_sphere("glass", 0.7, (-0.6, 0.5, 0.7), glass("glass"), segments=64, rings=32)
    S.plane("mirror", 1, (1.4, 1.0, 0.8), (math.pi / 2, 0, -0.6),
            S.glossy("mirror", 0.0, (0.95, 0.95, 0.95))).scale = (1.4, 1.6, 1)
    S.light('AREA', (-1.5, -1.0, 3.0), 200.0, target=(-0.6, 0.5, 0), size=0.25)
    scene.world.color = (0.01, 0.01, 0.01)
    S.camera((0.2, -5.0, 2.4), (0, 0.5, 0.5), lens=35)


def difficult_light(scene):
    """A small lamp inside a lampshade open only at the top: the room is lit from the ceiling."""
    S.room(size=4.0)
    shade = S.diffuse("shade", (0.8, 0.8, 0.8))
    for name, loc, rot in (("shade_a", (0, -0.25, 1.0), (math.pi / 2, 0, 0)),
                           ("shade_b", (0, 0.25, 1.0), (-math.pi / 2, 0, 0)),
                           ("shade_c", (-0.25, 0, 1.0), (0, -math.pi / 2, 0)),
                           ("shade_d", (0.25, 0, 1.0), (0, math.pi / 2, 0))):
        S.plane(name, 0.5, loc, rot, shade)
    S.plane("shade_floor", 0.5, (0, 0, 0.75), (0, 0, 0), shade)
    box("stand", (0.1, 0.1, 0.75), (0, 0, 0), S.diffuse("stand", (0.2, 0.2, 0.2)))
    S.light('POINT', (0, 0, 1.0), 150.0, shadow_soft_size=0.05)
    S.uv_sphere("ball", 0.5, (1.0, 0.6, 0.5), S.diffuse("ball", (0.8, 0.8, 0.8)))
    S.camera((0, -5.5, 2.0), (0, 0, 1.6), lens=30)


def _sky_image(width=512, height=256):
    """An equirectangular HDR sky: a blue gradient brightening to the horizon, a dim ground."""
    img = bpy.data.images.new("sky", width, height, float_buffer=True)
    v = (np.arange(height) + 0.5) / height  # 0 at the bottom row (straight down)
    elev = (v - 0.5) * math.pi
    sky = np.stack([0.3 + 0.5 * np.cos(elev), 0.5 + 0.5 * np.cos(elev), 1.2 + 0.3 * np.cos(elev)],
                   axis=1)
    ground = np.tile([0.15, 0.13, 0.1], (height, 1))
    rows = np.where((elev > 0)[:, None], sky, ground).astype(np.float32)
    rgba = np.ones((height, width, 4), np.float32)
    rgba[..., :3] = rows[:, None, :]
    img.pixels.foreach_set(rgba.ravel())
    img.pack()
    return img


def outdoor(scene):
    """Sun and an HDR sky over textured ground and objects."""
    world = scene.world
    world.use_nodes = True
    nt = world.node_tree
    env = nt.nodes.new("ShaderNodeTexEnvironment")
    env.image = _sky_image()
    bg = nt.nodes["Background"]
    nt.links.new(env.outputs["Color"], bg.inputs["Color"])
    ground_img = bpy.data.images.new("ground", 512, 512)
    ground_img.generated_type = 'COLOR_GRID'
    S.plane("ground", 40, (0, 0, 0), material=S.image_material("ground", ground_img))
    S.uv_sphere("ball", 0.8, (-1.2, 1.0, 0.8), S.diffuse("ball", (0.7, 0.25, 0.2)))
    box("crate", (1.2, 1.2, 1.2), (1.2, 1.5, 0), S.diffuse("crate", (0.6, 0.5, 0.3)), 0.5)
    box("wall", (6.0, 0.3, 1.5), (0, 4.0, 0), S.diffuse("wall", (0.7, 0.7, 0.68)))
    S.light('SUN', (0, 0, 10), 4.0, target=(1.5, 2.0, 0), angle=math.radians(1.0))
    S.camera((0.5, -6.0, 2.2), (0, 1.5, 0.5), lens=32)


def _procedural(name, texture, scale, bump_strength):
    """A Principled BSDF coloured by `texture` through a Color Ramp, bumped by its factor."""
    m, nt, out = S._material(name)
    bsdf = nt.nodes.new("ShaderNodeBsdfPrincipled")
    bsdf.inputs["Roughness"].default_value = 0.6
    tex = nt.nodes.new(texture)
    tex.inputs["Scale"].default_value = scale
    ramp = nt.nodes.new("ShaderNodeValToRGB")
    ramp.color_ramp.elements[0].color = (0.1, 0.15, 0.3, 1)
    ramp.color_ramp.elements[1].color = (0.9, 0.7, 0.4, 1)
    bump = nt.nodes.new("ShaderNodeBump")
    bump.inputs["Strength"].default_value = bump_strength
    fac = tex.outputs["Fac"] if "Fac" in tex.outputs else tex.outputs["Distance"]
    nt.links.new(fac, ramp.inputs["Fac"])
    nt.links.new(fac, bump.inputs["Height"])
    nt.links.new(ramp.outputs["Color"], bsdf.inputs["Base Color"])
    nt.links.new(bump.outputs["Normal"], bsdf.inputs["Normal"])
    nt.links.new(bsdf.outputs[0], out.inputs["Surface"])
    return m


def instances(scene):
    """Many instances of two meshes with Noise, Voronoi and Brick textures and bump."""
    S.plane("floor", 30, (0, 0, 0), material=_procedural("floor", "ShaderNodeTexBrick", 3.0, 0.4))
    mats = [_procedural("noise", "ShaderNodeTexNoise", 6.0, 0.3),
            _procedural("voronoi", "ShaderNodeTexVoronoi", 8.0, 0.3)]
    ball = S.uv_sphere("ball_0", 0.3, (0, 0, 0.3), mats[0], segments=32, rings=16)
    cube = box("cube_0", (0.5, 0.5, 0.5), (0, 0, 0), mats[1])
    rng = np.random.default_rng(7)
    for i in range(60):
        src = ball if i % 2 else cube
        obj = src.copy()  # shares the mesh: an instance
        obj.name = f"inst_{i}"
        obj.location = (rng.uniform(-3.5, 3.5), rng.uniform(-1.0, 5.0), src.location.z)
        obj.rotation_euler = (0, 0, rng.uniform(0, math.pi))
        if src is cube:  # each cube 1 mm taller than the last: no two tops coplanar (Cycles
            obj.scale.z = 1.0 + 0.001 * (i + 2)  # shadows overlapping coplanar faces, GDPT not)
        S.link(obj)
    S.light('AREA', (-2.0, -2.0, 4.0), 600.0, target=(0, 1.5, 0), size=2.0)
    scene.world.color = (0.15, 0.17, 0.2)
    S.camera((0, -5.5, 2.6), (0, 1.5, 0.2), lens=30)


SCENES = {
    "cornell_panel": cornell_panel,
    "interior": interior,
    "glossy": glossy,
    "glass_caustics": glass_caustics,
    "difficult_light": difficult_light,
    "outdoor": outdoor,
    "instances": instances,
}


def build(name, width, height):
    """Clears the current scene and builds scene `name` at width x height."""
    scene = S.clear()
    SCENES[name](scene)
    scene.render.resolution_x, scene.render.resolution_y = width, height
    return scene
