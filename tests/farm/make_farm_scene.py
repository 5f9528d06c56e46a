# The farm test's scene (run in Blender with the add-on): a small Cornell box with a glossy sphere
# and an emitter, G-PT with the Feature reconstruction (its passes too) and the Depth and Normal
# passes, so the EXR holds every kind of pass the merge handles. Saved twice: DIR/scene_GDPT.blend
# and, to be refused by gdpt-farm, DIR/scene_BLENDER_EEVEE.blend.
#   blender -b --factory-startup --addons gdpt --python make_farm_scene.py -- DIR
import math
import os
import sys

import bpy

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "blender"))
import scenes as S  # noqa: E402

out = sys.argv[sys.argv.index("--") + 1]
scene = S.clear()
S.room()
S.camera((0, -5.5, 2.0), (0, 0, 1.8), lens=28)
S.plane("panel", 1.0, (0, 0, 3.9), (math.pi, 0, 0), S.emission("panel", (1.0, 0.9, 0.8), 5.0))
S.uv_sphere("ball", 0.8, (0.3, 0.2, 0.8), S.glossy("gloss", 0.3), segments=24, rings=12)
S.setup_gdpt(scene, 12, mode='GPT', reconstruction='FEATURE', bounces=4, seed=5)
scene.render.resolution_x, scene.render.resolution_y = 40, 30
scene.view_layers[0].use_pass_z = True
scene.view_layers[0].use_pass_normal = True
for engine in ("GDPT", "BLENDER_EEVEE"):
    scene.render.engine = engine
    bpy.ops.wm.save_as_mainfile(filepath=os.path.join(out, f"scene_{engine}.blend"))
