# Builds the demo scene of `make demo` in Blender and saves it as a .blend (no binary files in
# git): a small Cornell box with a glass sphere, a brushed-metal sphere, a textured back wall and
# an area light, rendered by Gradient PT (G-PT, Feature reconstruction: at the demo's 32 samples and
# its Filter Glossy 1.0 it leaves 0.9 bright speckles per render against L1's 3.6 and 1.9x lower
# relMSE; 0.9 against 41.1 and 6.5x with Filter Glossy 0; bench/demo/speckles.py) to a PNG next
# to the .blend.
#   blender -b --python make_demo_scene.py -- OUT.blend
# Needs the gdpt add-on enabled (scripts/install-addon.sh does that).
import math
import os
import sys

import bpy
from mathutils import Vector

out_path = os.path.abspath(sys.argv[sys.argv.index("--") + 1])

# Start from an empty scene (keeps the preferences, so the add-on stays enabled).
bpy.ops.wm.read_homefile(use_empty=True)
scene = bpy.context.scene
scene.name = "GDPT demo"


def material(name, kind, **inputs):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    nt = m.node_tree
    nt.nodes.clear()
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    node = nt.nodes.new(kind)
    for key, value in inputs.items():
        node.inputs[key].default_value = value
    nt.links.new(node.outputs[0], out.inputs["Surface"])
    return m, node


def quad(name, size, location, rotation, mat):
    h = size / 2
    me = bpy.data.meshes.new(name)
    me.from_pydata([(-h, -h, 0), (h, -h, 0), (h, h, 0), (-h, h, 0)], [], [(0, 1, 2, 3)])
    uv = me.uv_layers.new(name="UVMap")
    for loop, coord in zip(me.loops, ((0, 0), (1, 0), (1, 1), (0, 1))):
        uv.data[loop.index].uv = coord
    me.materials.append(mat)
    obj = bpy.data.objects.new(name, me)
    obj.location, obj.rotation_euler = location, rotation
    scene.collection.objects.link(obj)
    return obj


def sphere(name, radius, location, mat):
    bpy.ops.mesh.primitive_uv_sphere_add(segments=64, ring_count=32, radius=radius,
                                         location=location)
    obj = bpy.context.active_object
    obj.name = name
    bpy.ops.object.shade_smooth()
    obj.data.materials.append(mat)
    return obj


white, _ = material("White", "ShaderNodeBsdfDiffuse", Color=(0.75, 0.75, 0.75, 1))
red, _ = material("Red", "ShaderNodeBsdfDiffuse", Color=(0.65, 0.08, 0.06, 1))
green, _ = material("Green", "ShaderNodeBsdfDiffuse", Color=(0.12, 0.5, 0.08, 1))
glass, glass_bsdf = material("Glass", "ShaderNodeBsdfGlass", Color=(1, 1, 1, 1), Roughness=0.0,
                            IOR=1.5)
glass_bsdf.distribution = 'SHARP'  # roughness 0 as a smooth glass (Blender 3.4's default: Beckmann)
metal, _ = material("Metal", "ShaderNodeBsdfPrincipled", **{
    "Base Color": (0.95, 0.7, 0.4, 1), "Metallic": 1.0, "Roughness": 0.25})

# Textured back wall: Blender's generated colour grid through an Image Texture node.
grid = bpy.data.images.new("Grid", 512, 512)
grid.generated_type = 'COLOR_GRID'
poster, poster_bsdf = material("Poster", "ShaderNodeBsdfPrincipled", Roughness=0.6)
tex = poster.node_tree.nodes.new("ShaderNodeTexImage")
tex.image = grid
poster.node_tree.links.new(tex.outputs["Color"], poster_bsdf.inputs["Base Color"])

size = 4.0
quad("Floor", size, (0, 0, 0), (0, 0, 0), white)
quad("Ceiling", size, (0, 0, size), (math.pi, 0, 0), white)
quad("Back", size, (0, size / 2, size / 2), (math.pi / 2, 0, 0), white)
quad("Poster", 2.0, (0, size / 2 - 0.01, 2.2), (math.pi / 2, 0, 0), poster)
quad("Left", size, (-size / 2, 0, size / 2), (0, math.pi / 2, 0), red)
quad("Right", size, (size / 2, 0, size / 2), (0, -math.pi / 2, 0), green)
sphere("Glass Ball", 0.7, (-0.8, -0.3, 0.7), glass)
sphere("Metal Ball", 0.7, (0.9, 0.6, 0.7), metal)

light = bpy.data.lights.new("Ceiling Light", 'AREA')
light.energy = 250.0
light.size = 1.0
lamp = bpy.data.objects.new("Ceiling Light", light)
lamp.location = (0, 0, size - 0.05)
scene.collection.objects.link(lamp)

cam = bpy.data.cameras.new("Camera")
cam.lens = 30
camera = bpy.data.objects.new("Camera", cam)
camera.location = (0, -6.2, 2.0)
camera.rotation_euler = (Vector((0, 0, 1.9)) - camera.location).to_track_quat('-Z', 'Y').to_euler()
scene.collection.objects.link(camera)
scene.camera = camera

world = bpy.data.worlds.new("World")
world.color = (0.02, 0.02, 0.02)
scene.world = world

scene.render.engine = 'GDPT'
scene.gdpt.samples = 32
scene.gdpt.mode = 'GPT'
scene.gdpt.reconstruction = 'FEATURE'
scene.gdpt.max_bounces = 6
scene.render.resolution_x, scene.render.resolution_y = 320, 240
scene.render.resolution_percentage = 100
scene.view_settings.view_transform = 'Filmic'
scene.frame_start = scene.frame_end = scene.frame_current = 1
scene.render.image_settings.file_format = 'PNG'
scene.render.filepath = "//demo_"
scene.render.use_file_extension = True

os.makedirs(os.path.dirname(out_path), exist_ok=True)
bpy.ops.wm.save_as_mainfile(filepath=out_path)
print("GDPT demo scene saved:", out_path)
