# Driver of scripts/ab-blender.sh (runs inside Blender): renders compare_cycles.py's Cornell or
# textured box (GDPT_AB_SCENE) at 96x72 with Gradient PT (PT, 4 bounces, Min Light Bounces 2,
# one render thread), a 16-spp warm-up, then GDPT_AB_REPS renders of GDPT_AB_SPP samples, and
# prints their render times (engine.LAST_RENDER["render"]) on one "AB" line.
import os
import sys

import bpy  # noqa: F401  (Blender's module: this runs inside Blender)

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, here)
sys.path.insert(0, os.path.join(here, "..", "..", "tests", "blender"))
import compare_cycles as C  # noqa: E402
import scenes as S  # noqa: E402

import gdpt.engine as engine  # noqa: E402

scene = S.clear()
getattr(C, os.environ.get("GDPT_AB_SCENE", "cornell"))(scene)
scene.render.resolution_x, scene.render.resolution_y = 96, 72
out = os.path.join(os.environ.get("TMPDIR", "/tmp"), f"gdpt_ab_{os.getpid()}.exr")


def render(spp):
    S.setup_gdpt(scene, spp, mode='PT', reconstruction='NONE', bounces=4, seed=1)
    scene.gdpt.min_light_bounces = 2
    scene.gdpt.threads = 1
    S.render(scene, out)
    return engine.LAST_RENDER["render"]


render(16)
spp, reps = int(os.environ.get("GDPT_AB_SPP", "512")), int(os.environ.get("GDPT_AB_REPS", "2"))
print("AB", " ".join(f"{render(spp):.3f}" for _ in range(reps)), flush=True)
os.remove(out)
