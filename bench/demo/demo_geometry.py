# Prints the demo scene's camera, spheres and lamp as `DEMO_GEOMETRY {json}`, for the
# analyses that trace the scene outside Blender (caustic_reach.py); run inside Blender on demo.blend.
import json
import sys

import bpy

bpy.ops.wm.open_mainfile(filepath=sys.argv[sys.argv.index("--") + 1])
scene = bpy.context.scene
cam, lamp = scene.camera, bpy.data.objects["Ceiling Light"]
ball, metal = bpy.data.objects["Glass Ball"], bpy.data.objects["Metal Ball"]
glass = next(n for n in bpy.data.materials["Glass"].node_tree.nodes if n.type == 'BSDF_GLASS')


def radius(obj):
    return max(v.co.length for v in obj.data.vertices) * obj.scale[0]


print("DEMO_GEOMETRY " + json.dumps({
    "resolution": [scene.render.resolution_x, scene.render.resolution_y],
    "camera_matrix": [list(row) for row in cam.matrix_world],
    "lens": cam.data.lens, "sensor_width": cam.data.sensor_width,
    "sensor_fit": cam.data.sensor_fit,
    "pixel_filter": [scene.gdpt.pixel_filter_type, scene.gdpt.filter_width],
    "ball_center": list(ball.location), "ball_radius": radius(ball),
    "metal_center": list(metal.location), "metal_radius": radius(metal),
    "ior": glass.inputs["IOR"].default_value,
    "lamp_center": list(lamp.location), "lamp_size": lamp.data.size,
    "lamp_rotation": list(lamp.rotation_euler), "lamp_shape": lamp.data.shape}), flush=True)
