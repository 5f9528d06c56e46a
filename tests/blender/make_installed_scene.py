# Writes a small GDPT scene (2 frames, multilayer EXR output next to it) for test_installed.sh.
# Runs in a Blender with the user's preferences, where install-addon.sh enabled the add-on.
import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(__file__))
import scenes as S  # noqa: E402

path = sys.argv[sys.argv.index("--") + 1]
scene = S.clear()
S.room()
S.camera((0, -5.5, 2.0), (0, 0, 1.6), lens=30)
S.light('AREA', (0, 0, 3.95), 150.0, target=(0, 0, 0), size=1.0)
ball = S.uv_sphere("ball", 0.7, (0, 0.3, 0.7), S.diffuse("ball", (0.8, 0.8, 0.8)))
ball.location.z = 0.7
ball.keyframe_insert("location", frame=1)
ball.location.z = 1.4
ball.keyframe_insert("location", frame=2)
S.setup_gdpt(scene, 16)
scene.frame_start, scene.frame_end = 1, 2
s = scene.render.image_settings
s.file_format = 'OPEN_EXR_MULTILAYER'
s.color_depth = '32'
scene.render.filepath = os.path.join(os.path.dirname(path), "frame_")
scene.render.use_file_extension = True
bpy.ops.wm.save_as_mainfile(filepath=path)
print("saved", path)
