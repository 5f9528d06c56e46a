# relMSE at 32 spp over several seeds, GDPT PT against Cycles at equal Min Light Bounces, each
# against its own 1024-spp reference, on compare_cycles.py's two scenes. compare_cycles.sh
# measures one seed, whose relMSE moved by up to 1.8x between seeds (fireflies).
#   BLENDER_USER_SCRIPTS=<staged add-on> MLB=0 blender -b --factory-startup --addons gdpt \
#     --python bench/blender/relmse_seeds.py -- --out out/bench/seeds
# Knobs (environment): MLB (Min Light Bounces in both engines, default 2), GDPT_BENCH_SEEDS
# (number of seeds, 8), GDPT_BENCH_SEED_REF_SAMPLES (samples of the references, 1024; one
# reference serves every seed, so its own error is in every seed's), GDPT_BENCH_SCENES
# (cornell,textured), GDPT_BENCH_DIFFUSE_BALL (1: the glossy ball made diffuse, which removes
# the caustic fireflies), GDPT_BENCH_ENGINES (GDPT,CYCLES; one of them alone to compare
# builds of one engine), and compare_cycles.py's GDPT_BENCH_BOUNCES and
# GDPT_BENCH_CYCLES_PATTERN. The references use seed 1000, outside the
# seeds measured: a 32-spp render of the reference's own seed is the first 32 samples of the
# reference in both engines, which would lower its error.
import os
import sys

import bpy
import numpy as np

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, here)
sys.path.insert(0, os.path.join(here, "..", "..", "tests", "blender"))
import compare_cycles as C  # noqa: E402
import scenes as S  # noqa: E402

SEEDS = range(1, int(os.environ.get("GDPT_BENCH_SEEDS", "8")) + 1)
SCENES = os.environ.get("GDPT_BENCH_SCENES", "cornell,textured").split(",")
DIFFUSE_BALL = os.environ.get("GDPT_BENCH_DIFFUSE_BALL", "0") == "1"
REFERENCE_SEED = 1000
REFERENCE_SAMPLES = int(os.environ.get("GDPT_BENCH_SEED_REF_SAMPLES", "1024"))
ENGINES = tuple(os.environ.get("GDPT_BENCH_ENGINES", "GDPT,CYCLES").split(","))


def main():
    out = S.args()["out"]
    os.makedirs(out, exist_ok=True)
    m = os.environ.get("MLB", "2")
    builds = {"cornell": C.cornell, "textured": C.textured}
    for name in SCENES:
        scene = S.clear()
        builds[name](scene)
        if DIFFUSE_BALL:
            ball = bpy.data.objects["b"]
            ball.data.materials.clear()
            ball.data.materials.append(S.diffuse("ball", (0.8, 0.8, 0.8)))
        refs = {e: C.render(scene, e, REFERENCE_SAMPLES, f"{out}/{name}_{e}_ref.exr", m,
                          REFERENCE_SEED)[1]
                for e in ENGINES}
        errs = {e: [S.rel_mse(C.render(scene, e, C.SAMPLES, f"{out}/{name}_{e}_{seed}.exr", m,
                                       seed)[1], refs[e]) for seed in SEEDS]
                for e in ENGINES}
        n = len(SEEDS)
        stats = {e: (np.array(errs[e]).mean(), np.array(errs[e]).std(ddof=1) / n ** 0.5)
                 for e in ENGINES}
        line = ", ".join(f"{e} relMSE {m:.5f} +- {se:.5f}" for e, (m, se) in stats.items())
        if len(ENGINES) == 2:
            g, c = np.array(errs["GDPT"]), np.array(errs["CYCLES"])
            line += (f"; ratio of means {g.mean() / c.mean():.3f}, per-seed ratios "
                     f"{np.round(g / c, 3).tolist()}")
        print(f"SEEDS {name}{' (diffuse ball)' if DIFFUSE_BALL else ''}, {C.BOUNCES} bounces, "
              f"min light bounces {m}, references {REFERENCE_SAMPLES} spp, Cycles pattern "
              f"{C.CYCLES_PATTERN}, {n} seeds: {line}", flush=True)


main()
