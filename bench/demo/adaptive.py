# Adaptive sampling on the demo (integrators/adaptive_sampling.h): per seed, the demo's Feature
# render at its own samples against one with adaptive sampling (up to --max-samples, at noise
# threshold --threshold, from --min-samples), both rendered and timed in this run: speckles and isolated speckles
# (speckles.py's definitions, against its converged reference), relMSE, the 99.9th percentile of
# the display error, the render call's seconds and the mean samples per pixel.
#   /usr/bin/python3 bench/demo/adaptive.py [--build build] [--seeds 4] --threshold T
#       --max-samples M [--min-samples N]
# Needs speckles.py's scene and reference (out/bench/demo: run speckles.py first). Writes
# bench/results/demo_adaptive.json.
import argparse
import json
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import speckles as SP  # noqa: E402

R, exr = SP.R, SP.exr


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--threshold", type=float, required=True)
    p.add_argument("--max-samples", type=int, required=True)
    p.add_argument("--min-samples", type=int, default=0, help="0: a quarter of the maximum")
    args, ref, out, blender = SP.demo_study("demo_adaptive", p)
    blend = ref.blend
    rows = {"uniform": [], "adaptive": []}
    try:
        samples = SP.demo_samples(blender, blend)
        for seed in range(1, args.seeds + 1):
            for name, n, threshold in (("uniform", samples, 0.0),
                                       ("adaptive", args.max_samples, args.threshold)):
                path = os.path.join(out, f"{name}_{seed}.exr")
                info = R.render(blender, blend, "gpt_feature", path, samples=n, seed=seed,
                                adaptive=threshold, adaptive_min=args.min_samples)
                counts = exr.read_exr(path)["ViewLayer.Sample Count.X"]
                rows[name].append({"seconds": info["seconds"],
                                   "mean_samples": float(counts.mean()),
                                   "max_samples": int(counts.max()), **ref.score(path)})
                r = rows[name][-1]
                print(f"seed {seed} {name:8s} {r['seconds']:.2f} s, {r['mean_samples']:.1f} "
                      f"samples per pixel (max {r['max_samples']}), speckles {r['speckles']}, "
                      f"relMSE {r['relmse']:.3e}", flush=True)
    finally:
        blender.close()
    result = {"demo_samples": samples, "threshold": args.threshold,
              "max_samples": args.max_samples, "min_samples": args.min_samples, "seeds": args.seeds,
              "commit": R.git("rev-parse", "--short", "HEAD"), "per_seed": rows}
    SP.summarise(result, rows, 8, extra=("mean_samples",))
    with open(os.path.join(SP.ROOT, "bench", "results", "demo_adaptive.json"), "w") as f:
        json.dump(result, f, indent=1)


if __name__ == "__main__":
    main()
