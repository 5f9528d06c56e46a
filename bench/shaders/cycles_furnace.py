# Cycles' directional albedo of one material: an orthographic camera looks at a plane (4 x 4 m,
# normal +z) under a uniform white world of strength 1 from direction (sin t, 0, cos t); a
# negative cos looks at the back face from below. Every camera ray scatters once and escapes, so
# the mean pixel value is the integral of f |cos| over the sphere (plus delta lobes).
# Usage: blender -b --factory-startup --python cycles_furnace.py -- CASE COS OUT.exr [SAMPLES]
# CASE: glossy_R | diffuse_R | glass_R_IOR | principled_r_g_b_metallic_specular_tint_R |
#       ptrans_r_g_b_tint_R_IOR_transmission
import bpy, sys, math, mathutils
argv = sys.argv[sys.argv.index("--") + 1:]
case, cos_t, out = argv[0], float(argv[1]), argv[2]
scene = bpy.context.scene
for o in list(bpy.data.objects):
    bpy.data.objects.remove(o)
bpy.ops.mesh.primitive_plane_add(size=4.0)
plane = bpy.context.active_object
mat = bpy.data.materials.new("m")
mat.use_nodes = True
nt = mat.node_tree
for n in list(nt.nodes):
    nt.nodes.remove(n)
outn = nt.nodes.new("ShaderNodeOutputMaterial")
if case.startswith("glossy"):
    b = nt.nodes.new("ShaderNodeBsdfGlossy"); b.distribution = "GGX"
    b.inputs["Roughness"].default_value = float(case.split("_")[1])
    b.inputs["Color"].default_value = (1, 1, 1, 1)
elif case.startswith("diffuse"):
    b = nt.nodes.new("ShaderNodeBsdfDiffuse")
    b.inputs["Roughness"].default_value = float(case.split("_")[1])
    b.inputs["Color"].default_value = (1, 1, 1, 1)
elif case.startswith("glass"):
    b = nt.nodes.new("ShaderNodeBsdfGlass"); b.distribution = "GGX"
    p = case.split("_")
    b.inputs["Roughness"].default_value = float(p[1])
    b.inputs["IOR"].default_value = float(p[2])
    b.inputs["Color"].default_value = (1, 1, 1, 1)
elif case.startswith("ptrans"):
    b = nt.nodes.new("ShaderNodeBsdfPrincipled"); b.distribution = "GGX"
    p = case.split("_")  # ptrans_r_g_b_tint_rough_ior_transmission
    b.inputs["Base Color"].default_value = (float(p[1]), float(p[2]), float(p[3]), 1)
    b.inputs["Specular Tint"].default_value = float(p[4])
    b.inputs["Roughness"].default_value = float(p[5])
    b.inputs["IOR"].default_value = float(p[6])
    b.inputs["Transmission"].default_value = float(p[7])
else:
    b = nt.nodes.new("ShaderNodeBsdfPrincipled"); b.distribution = "GGX"
    p = case.split("_")  # principled_base_r_g_b_metallic_specular_tint_roughness
    b.inputs["Base Color"].default_value = (float(p[1]), float(p[2]), float(p[3]), 1)
    b.inputs["Metallic"].default_value = float(p[4])
    b.inputs["Specular"].default_value = float(p[5])
    b.inputs["Specular Tint"].default_value = float(p[6])
    b.inputs["Roughness"].default_value = float(p[7])
nt.links.new(b.outputs[0], outn.inputs["Surface"])
plane.data.materials.append(mat)
world = bpy.data.worlds.new("w"); scene.world = world
world.use_nodes = True
world.node_tree.nodes["Background"].inputs["Color"].default_value = (1, 1, 1, 1)
world.node_tree.nodes["Background"].inputs["Strength"].default_value = 1.0
cam_data = bpy.data.cameras.new("c"); cam_data.type = "ORTHO"; cam_data.ortho_scale = 0.2
cam = bpy.data.objects.new("c", cam_data); scene.collection.objects.link(cam)
s = math.sqrt(1 - cos_t * cos_t)
cam.location = (s * 5, 0, cos_t * 5)
direction = mathutils.Vector((0, 0, 0)) - cam.location
cam.rotation_euler = direction.to_track_quat("-Z", "Y").to_euler()
scene.camera = cam
scene.render.engine = "CYCLES"
scene.cycles.device = "CPU"
scene.cycles.samples = int(argv[3]) if len(argv) > 3 else 512
scene.cycles.use_denoising = False
scene.cycles.max_bounces = 4
scene.cycles.sample_clamp_direct = 0; scene.cycles.sample_clamp_indirect = 0
scene.cycles.caustics_reflective = True
scene.render.resolution_x = 16; scene.render.resolution_y = 16
scene.render.film_transparent = False
scene.view_settings.view_transform = "Standard"
scene.render.image_settings.file_format = "OPEN_EXR"
scene.render.filepath = out
scene.render.threads_mode = "FIXED"; scene.render.threads = 1
bpy.ops.render.render(write_still=True)
