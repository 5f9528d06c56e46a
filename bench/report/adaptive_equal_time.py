# Adaptive sampling at equal time on the benchmark report's scenes (integrators/adaptive_sampling.h):
# per scene, G-PT + Feature rendered for --seconds with every pixel sampling and with adaptive
# sampling (--threshold, --min-samples), both in this run, relMSE against the report's cached PT
# reference halves, and their ratio (above 1: adaptive sampling is cleaner). Needs
# bench/results/cache from a report run (`make bench`).
#   /usr/bin/python3 bench/report/adaptive_equal_time.py --build build-dev --threshold T
#       [--seconds 10] [--min-samples 0] [--seeds 1] [--scenes a,b] [--tag NAME]
# Writes bench/results/adaptive_equal_time[_NAME].json.
import argparse
import json
import os
import sys
import tempfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, HERE)
import metrics as M  # noqa: E402
import run as R  # noqa: E402
import exr  # noqa: E402  (tests/blender, on the path run.py sets)


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--build", default="build")
    p.add_argument("--threshold", type=float, required=True)
    p.add_argument("--seconds", type=float, default=10.0)
    p.add_argument("--min-samples", type=int, default=0, help="0: automatic (64 here)")
    p.add_argument("--seeds", type=int, default=1)
    p.add_argument("--scenes", default=",".join(R.SCENES))
    p.add_argument("--cache", default=os.path.join(ROOT, "bench", "results", "cache"))
    p.add_argument("--tag", default="", help="suffix of the results file")
    args = p.parse_args()
    tmp = tempfile.mkdtemp(prefix="gdpt-adaptive-")
    blender = R.Blender(args.build)
    rows = {}
    try:
        for scene in args.scenes.split(","):
            cache = os.path.join(args.cache, f"{scene}_320x240")
            refs = [R.rgb(os.path.join(cache, f"ref_pt_{k}_40s.exr")) for k in (1, 2)]
            blend = os.path.join(cache, f"{scene}.blend")
            row = {"uniform": [], "adaptive": [], "uniform_samples": [],
                   "adaptive_mean_samples": []}
            for seed in range(1, args.seeds + 1):
                for name, threshold in (("uniform", 0.0), ("adaptive", args.threshold)):
                    out = os.path.join(tmp, f"{scene}_{name}_{seed}.exr")
                    R.render(blender, blend, "gpt_feature", out, seconds=args.seconds, seed=seed,
                             adaptive=threshold, adaptive_min=args.min_samples)
                    row[name].append(M.rel_mse_denoised(R.rgb(out), *refs))
                    counts = exr.read_exr(out)["ViewLayer.Sample Count.X"]
                    key = "uniform_samples" if name == "uniform" else "adaptive_mean_samples"
                    row[key].append(float(counts.mean()))
            row["uniform_over_adaptive"] = float(np.exp(np.mean(
                np.log(np.array(row["uniform"]) / np.array(row["adaptive"])))))
            rows[scene] = row
            print(f"{scene:16s} relMSE uniform {np.mean(row['uniform']):.3e} "
                  f"({np.mean(row['uniform_samples']):.0f} spp), adaptive "
                  f"{np.mean(row['adaptive']):.3e} ({np.mean(row['adaptive_mean_samples']):.0f} "
                  f"spp on average): uniform / adaptive {row['uniform_over_adaptive']:.2f}",
                  flush=True)
    finally:
        blender.close()
    result = {"threshold": args.threshold, "seconds": args.seconds,
              "min_samples": args.min_samples, "seeds": args.seeds,
              "commit": R.git("rev-parse", "--short", "HEAD"), "scenes": rows}
    name = "adaptive_equal_time" + (f"_{args.tag}" if args.tag else "") + ".json"
    with open(os.path.join(ROOT, "bench", "results", name), "w") as f:
        json.dump(result, f, indent=1)


if __name__ == "__main__":
    main()
