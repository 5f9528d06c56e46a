# Renders a 4x2 Non-Color image texture (through a Mapping node: scale 1.5, location -0.25)
# on an emissive plane seen by an orthographic camera, 12x12 px, one pixel = one uv point.
# Usage: blender -b --factory-startup --python cycles_texture.py -- Linear|Closest \
#        REPEAT|EXTEND|CLIP OUT.exr     (pixel values: shaders_texture_check)
import bpy, sys
argv = sys.argv[sys.argv.index("--") + 1:]
interp, ext, out = argv[0], argv[1], argv[2]
scene = bpy.context.scene
for o in list(bpy.data.objects): bpy.data.objects.remove(o)
bpy.ops.mesh.primitive_plane_add(size=2.0)
plane = bpy.context.active_object
img = bpy.data.images.new("t", 4, 2, alpha=True, float_buffer=True)
img.colorspace_settings.name = "Non-Color"
# row 0 (bottom) then row 1, RGBA
vals = []
for j in range(2):
    for i in range(4):
        vals += [i * 0.25 + 0.1, j * 0.5 + 0.2, (i + j) * 0.1, 1.0]
img.pixels = vals
mat = bpy.data.materials.new("m"); mat.use_nodes = True; nt = mat.node_tree
for n in list(nt.nodes): nt.nodes.remove(n)
o = nt.nodes.new("ShaderNodeOutputMaterial")
e = nt.nodes.new("ShaderNodeEmission")
t = nt.nodes.new("ShaderNodeTexImage"); t.image = img; t.interpolation = interp; t.extension = ext
m = nt.nodes.new("ShaderNodeMapping"); m.inputs["Scale"].default_value = (1.5, 1.5, 1)
m.inputs["Location"].default_value = (-0.25, -0.25, 0)
tc = nt.nodes.new("ShaderNodeTexCoord")
nt.links.new(tc.outputs["UV"], m.inputs["Vector"]); nt.links.new(m.outputs["Vector"], t.inputs["Vector"])
nt.links.new(t.outputs["Color"], e.inputs["Color"]); nt.links.new(e.outputs[0], o.inputs["Surface"])
plane.data.materials.append(mat)
world = bpy.data.worlds.new("w"); scene.world = world
world.use_nodes = True; world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0
cd = bpy.data.cameras.new("c"); cd.type = "ORTHO"; cd.ortho_scale = 2.0
cam = bpy.data.objects.new("c", cd); scene.collection.objects.link(cam); cam.location = (0, 0, 5)
scene.camera = cam
scene.render.engine = "CYCLES"; scene.cycles.samples = 16; scene.cycles.use_denoising = False
scene.cycles.filter_width = 0.01
scene.render.resolution_x = 12; scene.render.resolution_y = 12
scene.view_settings.view_transform = "Standard"
scene.render.image_settings.file_format = "OPEN_EXR"; scene.render.filepath = out
bpy.ops.render.render(write_still=True)
