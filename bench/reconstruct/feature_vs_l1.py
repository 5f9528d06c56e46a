# Feature against L1 at equal samples on the benchmark scenes: one G-PT render with the Feature
# reconstruction (which writes the primal and gradient halves and the feature passes), its
# Combined against gdpt-reconstruct --norm l1 on the same passes, both against the report's
# cached GDPT PT reference (bench/results/cache/<scene>_320x240/ref_pt_{1,2}_40s.exr, made by
# `make bench`). Sample counts default to what G-PT reached in 40 s in the committed report.
#   /usr/bin/python3 bench/reconstruct/feature_vs_l1.py --build build [--scenes a,b] [--cache DIR]
#                                                         [--resolve]
# --resolve: no rendering; the renders already in --out are solved again with both norms (for a
# change to the reconstruction alone).
# Prints one line per scene and writes bench/results/feature_vs_l1.json (a run over --scenes
# replaces only those scenes).
import json
import os
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "bench", "report"))
import metrics as M  # noqa: E402
import run as R  # noqa: E402

def samples_at_40s(scene):
    with open(os.path.join(ROOT, "bench", "results", f"{scene}.json")) as f:
        curve = json.load(f)["curves"]["gpt_l1"]
    return next(p["samples"] for p in curve if p["budget"] == 40)


def main():
    p = R.rendered_scenes_parser("feature_vs_l1")
    args = p.parse_args()
    os.makedirs(args.out, exist_ok=True)
    blender = None if args.resolve else R.Blender(args.build)
    commit, rows = R.git("rev-parse", "--short", "HEAD"), {}
    try:
        for scene in args.scenes.split(","):
            cache = os.path.join(args.cache, f"{scene}_320x240")
            refs = [R.rgb(os.path.join(cache, f"ref_pt_{i}_40s.exr")) for i in (1, 2)]
            spp = samples_at_40s(scene)
            path = os.path.join(args.out, f"{scene}.exr")
            if args.resolve:  # the samples the render was made with
                attrs = R.exr.read_string_attributes(path)
                info = {"samples": int(attrs.get("gdpt.ViewLayer.samples", spp))}
            else:
                info = R.render(blender, os.path.join(cache, f"{scene}.blend"), "gpt_feature",
                                path, samples=spp, seed=7)
            t0 = time.perf_counter()
            l1, _ = R.solve(args.build, path, "l1", path[:-4] + "_l1.exr")
            t_l1 = time.perf_counter() - t0
            t0 = time.perf_counter()
            solved, _ = R.solve(args.build, path, "feature", path[:-4] + "_feature.exr")
            t_feature = time.perf_counter() - t0
            feature = solved if args.resolve else R.rgb(path)
            row = {"scene": scene, "samples": info["samples"],
                   "relmse_l1": M.rel_mse_denoised(l1, *refs),
                   "relmse_feature": M.rel_mse_denoised(feature, *refs),
                   "cli_seconds_l1": t_l1, "cli_seconds_feature": t_feature,
                   "commit": commit, "resolved": args.resolve}
            row["l1_over_feature"] = row["relmse_l1"] / row["relmse_feature"]
            rows[scene] = row
            print(f"{scene:16s} {row['samples']:5d} spp  relMSE L1 {row['relmse_l1']:.3e}  "
                  f"Feature {row['relmse_feature']:.3e}  L1 / Feature {row['l1_over_feature']:.2f}x"
                  f"  (gdpt-reconstruct {t_l1:.1f} s / {t_feature:.1f} s)", flush=True)
    finally:
        if blender:
            blender.close()
    R.update_scene_results("feature_vs_l1.json", rows)


if __name__ == "__main__":
    main()
