# Builds one benchmark scene and saves it (runs inside Blender):
#   blender -b --factory-startup --python bench/scenes/build.py -- NAME OUT.blend [WIDTHxHEIGHT]
import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import catalog  # noqa: E402

argv = sys.argv[sys.argv.index("--") + 1:]
name, path = argv[0], os.path.abspath(argv[1])
width, height = (int(v) for v in (argv[2] if len(argv) > 2 else "320x240").split("x"))
if name not in catalog.SCENES:
    sys.exit(f"build.py: unknown scene '{name}' (known: {', '.join(catalog.SCENES)})")
catalog.build(name, width, height)
bpy.ops.wm.save_as_mainfile(filepath=path, compress=True)
print(f"BENCH scene {name} {width}x{height} -> {path}")
