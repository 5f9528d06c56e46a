# Reference numbers for test_cycles_reference.cpp: renders a small white Lambert plane at the
# origin (normal +Z) under one light with Cycles, 0 bounces, Standard view transform, and prints
# the mean radiance of the 8x8 image (albedo 1: radiance = E / pi).
# Usage: blender -b --factory-startup --python cycles_reference.py -- KIND [SAMPLES]
#   KIND: area, area_scaled, disk, point, point_radius, spot, spot_radius, sun, world,
#   world_rotated, mesh_back. Writes /tmp/lights_cycles/out_KIND.exr.
import bpy, math, sys
argv = sys.argv[sys.argv.index("--") + 1:]
kind = argv[0]
bpy.ops.wm.read_factory_settings(use_empty=True)
sc = bpy.context.scene
sc.render.engine = 'CYCLES'
sc.cycles.device = 'CPU'
sc.cycles.samples = int(argv[1]) if len(argv) > 1 else 256
sc.cycles.max_bounces = 0
sc.cycles.use_denoising = False
sc.render.resolution_x = sc.render.resolution_y = 8
sc.render.film_transparent = False
sc.view_settings.view_transform = 'Standard'
sc.view_settings.look = 'None'
sc.world = bpy.data.worlds.new("w")
sc.world.use_nodes = True
sc.world.node_tree.nodes["Background"].inputs[1].default_value = 0.0
bpy.ops.mesh.primitive_plane_add(size=0.02, location=(0, 0, 0))
mat = bpy.data.materials.new("white"); mat.use_nodes = True
nt = mat.node_tree; nt.nodes.clear()
d = nt.nodes.new("ShaderNodeBsdfDiffuse"); d.inputs[0].default_value = (1, 1, 1, 1)
o = nt.nodes.new("ShaderNodeOutputMaterial"); nt.links.new(d.outputs[0], o.inputs[0])
bpy.context.object.data.materials.append(mat)
cam = bpy.data.cameras.new("c"); cam.type = 'ORTHO'; cam.ortho_scale = 0.01
co = bpy.data.objects.new("c", cam); sc.collection.objects.link(co); sc.camera = co
co.location = (0, 0, 0.5)   # looks down -Z
if kind == "area":
    l = bpy.data.lights.new("l", 'AREA'); l.shape = 'SQUARE'; l.size = 1.0; l.energy = 100.0
    lo = bpy.data.objects.new("l", l); lo.location = (0, 0, 2)
elif kind == "area_scaled":
    l = bpy.data.lights.new("l", 'AREA'); l.shape = 'RECTANGLE'; l.size = 1.0; l.size_y = 0.5; l.energy = 100.0
    lo = bpy.data.objects.new("l", l); lo.location = (0, 0, 2); lo.scale = (2, 1, 1)
elif kind == "disk":
    l = bpy.data.lights.new("l", 'AREA'); l.shape = 'DISK'; l.size = 2.0; l.energy = 100.0
    lo = bpy.data.objects.new("l", l); lo.location = (0, 0, 1.5)
elif kind == "point":
    l = bpy.data.lights.new("l", 'POINT'); l.shadow_soft_size = 0.0; l.energy = 100.0
    lo = bpy.data.objects.new("l", l); lo.location = (0, 0, 3)
elif kind == "point_radius":
    l = bpy.data.lights.new("l", 'POINT'); l.shadow_soft_size = 0.5; l.energy = 100.0
    lo = bpy.data.objects.new("l", l); lo.location = (0, 0, 1.5)
elif kind == "spot_radius":
    l = bpy.data.lights.new("l", 'SPOT'); l.shadow_soft_size = 0.3; l.energy = 80.0
    l.spot_size = 0.8; l.spot_blend = 0.6
    lo = bpy.data.objects.new("l", l); lo.location = (0.4, 0, 1.5)
elif kind == "spot":
    l = bpy.data.lights.new("l", 'SPOT'); l.shadow_soft_size = 0.0; l.energy = 100.0
    l.spot_size = 1.0; l.spot_blend = 0.5
    lo = bpy.data.objects.new("l", l); lo.location = (3 * math.tan(0.35), 0, 3)
elif kind == "sun":
    l = bpy.data.lights.new("l", 'SUN'); l.energy = 3.0; l.angle = math.radians(10)
    lo = bpy.data.objects.new("l", l); lo.rotation_euler = (math.radians(30), 0, 0)
if kind == "mesh_back":
    # 1 x 1 m emission plane (strength 2) at z = 1 with its normal up (+Z): the receiver below
    # sees its back face; Cycles' mesh lights emit on both sides.
    bpy.ops.mesh.primitive_plane_add(size=1.0, location=(0.2, 0.1, 1.0))
    em = bpy.data.materials.new("em"); em.use_nodes = True
    ent = em.node_tree; ent.nodes.clear()
    e = ent.nodes.new("ShaderNodeEmission"); e.inputs[1].default_value = 2.0
    eo = ent.nodes.new("ShaderNodeOutputMaterial"); ent.links.new(e.outputs[0], eo.inputs[0])
    bpy.context.object.data.materials.append(em)
    co.location = (0, 0, 0.5)
elif kind.startswith("world"):
    # 16 x 8 scene-linear image with the formula of test_cycles_reference.cpp; the plane and the
    # camera are tilted 60 degrees towards +X so that the image's orientation matters.
    W, H = 16, 8
    img = bpy.data.images.new("env", W, H, float_buffer=True)
    pix = []
    for y in range(H):
        for x in range(W):
            pix += [0.1 + ((x * 7 + y * 3) % 11) * 0.3, 0.2 + ((x * 5 + y * 11) % 7) * 0.25,
                    0.05 + ((x * 3 + y * 5) % 13) * 0.1, 1.0]
    img.pixels = pix
    wn = sc.world.node_tree
    bg = wn.nodes["Background"]
    bg.inputs[1].default_value = 0.7
    env = wn.nodes.new("ShaderNodeTexEnvironment"); env.image = img
    wn.links.new(env.outputs[0], bg.inputs[0])
    if kind == "world_rotated":
        tc = wn.nodes.new("ShaderNodeTexCoord"); mp = wn.nodes.new("ShaderNodeMapping")
        mp.inputs["Rotation"].default_value = (0.0, 0.0, math.radians(90))
        wn.links.new(tc.outputs["Generated"], mp.inputs[0]); wn.links.new(mp.outputs[0], env.inputs[0])
    plane = [o for o in sc.objects if o.type == 'MESH'][0]
    plane.rotation_euler = (0, math.radians(60), 0)
    co.rotation_euler = (0, math.radians(60), 0)
    co.location = (0.5 * math.sin(math.radians(60)), 0, 0.5 * math.cos(math.radians(60)))
else:
    sc.collection.objects.link(lo)
sc.render.image_settings.file_format = 'OPEN_EXR'
import os
os.makedirs("/tmp/lights_cycles", exist_ok=True)
sc.render.filepath = "/tmp/lights_cycles/out_" + kind + ".exr"
bpy.ops.render.render(write_still=True)
img = bpy.data.images.load(sc.render.filepath)
px = list(img.pixels)
w = img.size[0]; h = img.size[1]
vals = [px[(y * w + x) * 4] for y in range(h) for x in range(w)]
print("RESULT", kind, sum(vals) / len(vals))
