# Shadow caustics (manifold next-event estimation, integrators/common/manifold_nee.h) on the
# demo: per seed, the demo's Feature render at its own samples without and with Cycles' Shadow
# Caustics (the glass sphere casting, every other mesh receiving, the lamp lighting them), both
# rendered and timed in this run, scored as speckles.py scores (against its converged reference,
# rendered without them): speckles, isolated speckles, relMSE, the display error's 99.9th
# percentile, the render call's seconds.
#   /usr/bin/python3 bench/demo/shadow_caustics.py [--build build] [--seeds 4]
# Needs speckles.py's scene and reference (out/bench/demo: run speckles.py first). Writes
# bench/results/demo_shadow_caustics.json.
import json
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import speckles as SP  # noqa: E402

R = SP.R
CASTER = "Glass Ball"  # make_demo_scene.py's glass sphere


def main():
    args, ref, out, blender = SP.demo_study("demo_shadow_caustics")
    rows = {"plain": [], "shadow_caustics": []}
    try:
        samples = SP.demo_samples(blender, ref.blend)
        for seed in range(1, args.seeds + 1):
            for name, caster in (("plain", None), ("shadow_caustics", CASTER)):
                path = os.path.join(out, f"{name}_{seed}.exr")
                info = R.render(blender, ref.blend, "gpt_feature", path, samples=samples,
                                seed=seed, shadow_caustics=caster)
                rows[name].append({"seconds": info["seconds"], **ref.score(path)})
                r = rows[name][-1]
                print(f"seed {seed} {name:15s} {r['seconds']:.2f} s, speckles {r['speckles']}, "
                      f"relMSE {r['relmse']:.3e}", flush=True)
    finally:
        blender.close()
    result = {"demo_samples": samples, "seeds": args.seeds,
              "commit": R.git("rev-parse", "--short", "HEAD"), "per_seed": rows}
    SP.summarise(result, rows, 15)
    with open(os.path.join(SP.ROOT, "bench", "results", "demo_shadow_caustics.json"), "w") as f:
        json.dump(result, f, indent=1)


if __name__ == "__main__":
    main()
