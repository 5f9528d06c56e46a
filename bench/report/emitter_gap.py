# Who is right where the report's engines disagree on cornell_panel (its "refs agree" column):
# an emissive panel 5 mm below the ceiling, whose light escapes from the gap onto the ceiling and
# the upper walls. Renders the report's cached scene (bench/results/cache, made by `make bench`)
# with GDPT PT, Cycles unbiased (light sampling with MIS, its default) and Cycles unbiased with
# the emitters found by BSDF rays alone (the material's Multiple Importance off: the plainest
# estimator, no light sampling), two seeds each at fixed samples, and prints each region's mean
# luminance (ceiling without the panel, back wall and boxes, floor) with half the two seeds'
# difference, and each estimator over the BSDF-only one.
#   /usr/bin/python3 bench/report/emitter_gap.py [--build build] [--samples 1024]
# Writes bench/results/emitter_gap.json.
import argparse
import json
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, HERE)
import metrics as M  # noqa: E402
import run as R  # noqa: E402

# method: samples as a multiple of --samples (BSDF-only is the noisiest)
METHODS = {"pt": 1, "cycles_unbiased": 1, "cycles_bsdf": 2}


def regions(lum):
    """Masks of a 320x240 frame of cornell_panel (rows from the bottom, Blender's order)."""
    h, w = lum.shape
    y, x = np.mgrid[0:h, 0:w]
    inner = (x > 60) & (x < 260)
    return {"ceiling": (y >= 175) & (lum < 2.0), "back wall and boxes": (y >= 60) & (y < 170) & inner,
            "floor": (y < 50) & inner}


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--build", default="build")
    p.add_argument("--samples", type=int, default=1024)
    p.add_argument("--cache", default=os.path.join(ROOT, "bench", "results", "cache"))
    p.add_argument("--out", default=os.path.join(ROOT, "out", "bench", "emitter_gap"))
    args = p.parse_args()
    os.makedirs(args.out, exist_ok=True)
    blend = os.path.join(args.cache, "cornell_panel_320x240", "cornell_panel.blend")
    blender = R.Blender(args.build)
    lum = {}
    try:
        for method, scale in METHODS.items():
            lum[method] = []
            for seed in (1, 2):
                path = os.path.join(args.out, f"{method}_{seed}.exr")
                R.render(blender, blend, method, path, samples=args.samples * scale, seed=seed)
                lum[method].append(M.luminance(R.rgb(path)))
    finally:
        blender.close()
    masks = regions(np.mean([img for imgs in lum.values() for img in imgs], axis=0))
    result = {"commit": R.git("rev-parse", "--short", "HEAD"), "samples": args.samples,
              "regions": {}}
    for name, mask in masks.items():
        row = {}
        for method, imgs in lum.items():
            a, b = (float(img[mask].mean()) for img in imgs)
            row[method] = {"mean": (a + b) / 2, "half_difference": abs(a - b) / 2}
        for method in METHODS:
            row[method]["over_bsdf_only"] = row[method]["mean"] / row["cycles_bsdf"]["mean"]
        result["regions"][name] = row
        print(f"{name:20s} " + "  ".join(
            f"{m} {v['mean']:.5f} +- {v['half_difference']:.5f} ({v['over_bsdf_only']:.4f})"
            for m, v in row.items()), flush=True)
    with open(os.path.join(ROOT, "bench", "results", "emitter_gap.json"), "w") as f:
        json.dump(result, f, indent=1)


if __name__ == "__main__":
    main()
