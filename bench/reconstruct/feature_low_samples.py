# Feature against L1 at the benchmark report's lowest budget, over several seeds: one render is
# one draw of G-PT's image-wide camera jitter (render/sampler.h), and at ~18 samples per half a
# single draw can decide a scene's ratio. For each scene and seed: a G-PT + Feature render with
# the samples the report's Feature render reached at the budget, and a plain G-PT render with the
# samples its L1 render reached, solved with gdpt-reconstruct --norm l1; also L1 on the Feature
# render's passes (what the halves cost the image of all samples), and how the halves' estimate
# of the Feature render's noise compares with its true error (metrics.half_noise_ratio). All
# against the report's cached GDPT PT reference (bench/results/cache, made by `make bench`).
#   /usr/bin/python3 bench/reconstruct/feature_low_samples.py --build build [--budget 5]
#                                                             [--seeds 7,1,2,3,4] [--scenes a,b]
#                                                             [--counts F,L] [--resolve]
# --resolve: no rendering; the Feature renders already in --out are solved again by this build's
# gdpt-reconstruct --norm feature (for a change to the reconstruction alone).
# Prints one line per scene and seed, then per scene the mean relMSE of each and the ratio of the
# means; writes bench/results/feature_low_samples.json (another budget: ..._<budget>s.json), where
# a run over --scenes replaces only those scenes.
import json
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "bench", "report"))
import metrics as M  # noqa: E402
import run as R  # noqa: E402

def samples_at(scene, curve, budget):
    with open(os.path.join(ROOT, "bench", "results", f"{scene}.json")) as f:
        points = json.load(f)["curves"][curve]
    return next(p["samples"] for p in points if p["budget"] == budget)


def measure(blender, args, scene, seed):
    cache = os.path.join(args.cache, f"{scene}_320x240")
    refs = [R.rgb(os.path.join(cache, f"ref_pt_{i}_40s.exr")) for i in (1, 2)]
    blend = os.path.join(cache, f"{scene}.blend")
    feat = os.path.join(args.out, f"{scene}_feature_{seed}.exr")
    plain = os.path.join(args.out, f"{scene}_gpt_{seed}.exr")
    if args.counts:
        spp_f, spp_l1 = map(int, args.counts.split(","))
    else:
        spp_f = samples_at(scene, "gpt_feature", args.budget)
        spp_l1 = samples_at(scene, "gpt_l1", args.budget)
    if args.resolve:
        feature, _ = R.solve(args.build, feat, "feature", feat[:-4] + "_resolved.exr")
    else:
        R.render(blender, blend, "gpt_feature", feat, samples=spp_f, seed=seed)
        R.render(blender, blend, "gpt", plain, samples=spp_l1, seed=seed)
        feature = R.rgb(feat)
    l1, _ = R.solve(args.build, plain, "l1", plain[:-4] + "_l1.exr")
    l1_halves, _ = R.solve(args.build, feat, "l1", feat[:-4] + "_l1.exr")
    # What the halves say the noise of the Feature render's primal is, over its true error.
    a, b, primal, emission = (R.rgb(feat, f"ViewLayer.{name}.")
                              for name in ("Primal A", "Primal B", "Primal", "Emission"))
    return {"seed": seed, "samples_feature": spp_f, "samples_l1": spp_l1,
            "half_noise_ratio": M.half_noise_ratio(a + emission, b + emission,
                                                   primal + emission, *refs),
            "relmse_feature": M.rel_mse_denoised(feature, *refs),
            "relmse_l1": M.rel_mse_denoised(l1, *refs),
            "relmse_l1_on_feature_render": M.rel_mse_denoised(l1_halves, *refs)}


def main():
    p = R.rendered_scenes_parser("feature_low_samples")
    p.add_argument("--budget", type=int, default=5)
    p.add_argument("--seeds", default="7,1,2,3,4")
    p.add_argument("--counts", help="FEATURE,L1 sample counts instead of the report's at the "
                   "budget (when the host's speed skewed that run's counts)")
    args = p.parse_args()
    os.makedirs(args.out, exist_ok=True)
    blender = None if args.resolve else R.Blender(args.build)
    commit, entries = R.git("rev-parse", "--short", "HEAD"), {}
    try:
        for scene in args.scenes.split(","):
            rows = []
            for seed in map(int, args.seeds.split(",")):
                r = measure(blender, args, scene, seed)
                rows.append(r)
                print(f"{scene:16s} seed {seed:2d}  Feature {r['relmse_feature']:.3e} "
                      f"({r['samples_feature']} spp)  L1 {r['relmse_l1']:.3e} ({r['samples_l1']} "
                      f"spp)  L1 on the Feature render {r['relmse_l1_on_feature_render']:.3e}",
                      flush=True)
            mean = {k: float(np.mean([r[k] for r in rows]))
                    for k in ("relmse_feature", "relmse_l1", "relmse_l1_on_feature_render",
                              "half_noise_ratio")}
            wins = sum(r["relmse_feature"] < r["relmse_l1"] for r in rows)
            entries[scene] = {"per_seed": rows, "mean": mean, "feature_lower": wins,
                              "l1_over_feature": mean["relmse_l1"] / mean["relmse_feature"],
                              "commit": commit, "resolved": args.resolve}
            print(f"{scene:16s} mean  Feature {mean['relmse_feature']:.3e}  L1 {mean['relmse_l1']:.3e}"
                  f"  L1 / Feature {mean['relmse_l1'] / mean['relmse_feature']:.2f}x  Feature lower "
                  f"in {wins} of {len(rows)}  (L1 on the Feature render {mean['relmse_l1_on_feature_render']:.3e};"
                  f" the halves' noise over the true {mean['half_noise_ratio']:.2f})",
                  flush=True)
    finally:
        if blender:
            blender.close()
    name = "feature_low_samples" + ("" if args.budget == 5 else f"_{args.budget}s") + ".json"
    R.update_scene_results(name, entries, budget=args.budget)


if __name__ == "__main__":
    main()
