# Prints the demo scene's own sample count (`DEMO_SAMPLES n`); run inside Blender on demo.blend.
import sys

import bpy

bpy.ops.wm.open_mainfile(filepath=sys.argv[sys.argv.index("--") + 1])
print(f"DEMO_SAMPLES {bpy.context.scene.gdpt.samples}", flush=True)
