# Prints the demo scene's camera, glass sphere and lamp as `DEMO_GEOMETRY {json}`, for the
# analyses that trace the scene outside Blender (caustic_reach.py); run inside Blender on demo.blend.
import json
import sys

import bpy

bpy.ops.wm.open_mainfile(filepath=sys.argv[sys.argv.index("--") + 1])
scene = bpy.context.scene
cam, ball, lamp = scene.camera, bpy.data.objects["Glass Ball"], bpy.data.objects["Ceiling Light"]
glass = next(n for n in bpy.data.materials["Glass"].node_tree.nodes if n.type == 'BSDF_GLASS')
radius = max(v.co.length for v in ball.data.vertices) * ball.scale[0]
print("DEMO_GEOMETRY " + json.dumps({
    "resolution": [scene.render.resolution_x, scene.render.resolution_y],
    "camera_matrix": [list(row) for row in cam.matrix_world],
    "lens": cam.data.lens, "sensor_width": cam.data.sensor_width,
    "sensor_fit": cam.data.sensor_fit,
    "ball_center": list(ball.location), "ball_radius": radius,
    "ior": glass.inputs["IOR"].default_value,
    "lamp_center": list(lamp.location), "lamp_size": lamp.data.size,
    "lamp_rotation": list(lamp.rotation_euler), "lamp_shape": lamp.data.shape}), flush=True)
