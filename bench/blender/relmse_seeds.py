# relMSE at 32 spp over 8 seeds, GDPT PT against Cycles at equal Min Light Bounces (MLB, default 2),
# each against its own 1024-spp reference, on compare_cycles.py's two scenes. compare_cycles.sh
# measures one seed, whose relMSE moved by up to 1.8x between seeds (fireflies).
#   BLENDER_USER_SCRIPTS=<staged add-on> MLB=0 blender -b --factory-startup --addons gdpt \
#     --python bench/blender/relmse_seeds.py -- --out out/bench/seeds
import os
import sys

import numpy as np

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, here)
sys.path.insert(0, os.path.join(here, "..", "..", "tests", "blender"))
import compare_cycles as C  # noqa: E402
import scenes as S  # noqa: E402

SEEDS = range(1, 9)


def main():
    out = S.args()["out"]
    os.makedirs(out, exist_ok=True)
    m = os.environ.get("MLB", "2")
    engines = ("GDPT", "CYCLES")
    for name, build in (("cornell", C.cornell), ("textured", C.textured)):
        scene = S.clear()
        build(scene)
        refs = {e: C.render(scene, e, 1024, f"{out}/{name}_{e}_ref.exr", m)[1] for e in engines}
        errs = {e: [S.rel_mse(C.render(scene, e, C.SAMPLES, f"{out}/{name}_{e}_{seed}.exr", m,
                                       seed)[1], refs[e]) for seed in SEEDS]
                for e in engines}
        g, c = np.array(errs["GDPT"]), np.array(errs["CYCLES"])
        n = len(SEEDS)
        print(f"SEEDS {name} min light bounces {m}: GDPT relMSE {g.mean():.5f} +- "
              f"{g.std(ddof=1) / n ** 0.5:.5f}, Cycles {c.mean():.5f} +- "
              f"{c.std(ddof=1) / n ** 0.5:.5f}; ratio of means {g.mean() / c.mean():.3f}, "
              f"per-seed ratios {np.round(g / c, 3).tolist()}", flush=True)


main()
