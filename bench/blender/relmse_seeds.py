# relMSE at 32 spp over 8 seeds, GDPT PT against Cycles at equal Min Light Bounces (MLB, default 2),
# each against its own 1024-spp reference, on compare_cycles.py's two scenes. compare_cycles.sh
# measures one seed, whose relMSE moved by up to 1.8x between seeds (fireflies).
#   BLENDER_USER_SCRIPTS=<staged add-on> MLB=0 blender -b --factory-startup --addons gdpt \
#     --python bench/blender/relmse_seeds.py -- --out out/bench/seeds
import os, sys
here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(here, "..", "..", "tests", "blender"))
import bpy
import numpy as np
import scenes as S
src = open(os.path.join(here, "compare_cycles.py")).read()
exec(src[:src.index("def main():")])  # its scenes and render(), without its main()
out = S.args()["out"]
os.makedirs(out, exist_ok=True)
M = os.environ.get("MLB", "2")
for name, build in (("cornell", cornell), ("textured", textured)):
    scene = S.clear(); build(scene)
    refs = {e: render(scene, e, 1024, f"{out}/{name}_{e}_ref.exr", M)[1] for e in ("GDPT", "CYCLES")}
    errs = {"GDPT": [], "CYCLES": []}
    for seed in range(1, 9):
        for e in ("GDPT", "CYCLES"):
            if e == "GDPT":
                S.setup_gdpt(scene, 32, mode='PT', reconstruction='NONE', bounces=BOUNCES, seed=seed)
                scene.gdpt.min_light_bounces = int(M)
            else:
                S.setup_cycles(scene, 32, bounces=BOUNCES, seed=seed)
                scene.cycles.min_light_bounces = int(M)
            scene.render.resolution_x, scene.render.resolution_y = RES
            p = S.render(scene, f"{out}/{name}_{e}_{seed}.exr")
            errs[e].append(S.rel_mse(S.read_rgb(p), refs[e]))
    g, c = np.array(errs["GDPT"]), np.array(errs["CYCLES"])
    r = g / c
    print(f"SEEDS {name} min light bounces {M}: GDPT relMSE {g.mean():.5f} +- {g.std(ddof=1)/8**0.5:.5f}, "
          f"Cycles {c.mean():.5f} +- {c.std(ddof=1)/8**0.5:.5f}; ratio of means {g.mean()/c.mean():.3f}, "
          f"per-seed ratios {np.round(r, 3).tolist()}", flush=True)
