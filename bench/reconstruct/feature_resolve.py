# The benchmark report's cached Feature renders solved again by a build's gdpt-reconstruct, per
# scene and budget: relMSE against the cached PT reference halves and L1 / Feature, L1 being the
# cached L1 image of the same budget's plain G-PT render (equal budget, as the report's per-budget
# table). For judging a change to the reconstruction in a minute, without rewriting the report
# (`bench/report/run.py --doc-only --resolve-feature` does that). Needs bench/results/cache from a
# report run (`make bench`).
#   /usr/bin/python3 bench/reconstruct/feature_resolve.py --build build-dev [--scenes a,b]
#                                                          [--extra "--flag value"]
# Prints one line per scene and the geometric mean of L1 / Feature; writes only to a temporary
# folder.
import argparse
import os
import subprocess
import sys
import tempfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "bench", "report"))
import metrics as M  # noqa: E402
import run as R  # noqa: E402

BUDGETS = (5, 10, 20, 40)


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--build", default="build")
    p.add_argument("--scenes", default=",".join(R.SCENES))
    p.add_argument("--cache", default=os.path.join(ROOT, "bench", "results", "cache"))
    p.add_argument("--extra", default="", help="more gdpt-reconstruct arguments")
    args = p.parse_args()
    cli = os.path.join(args.build, "reconstruct", "gdpt-reconstruct")
    tmp = tempfile.mkdtemp(prefix="gdpt-feature-resolve-")
    logs = []
    for scene in args.scenes.split(","):
        cache = os.path.join(args.cache, f"{scene}_320x240")
        refs = [R.rgb(os.path.join(cache, f"ref_pt_{k}_40s.exr")) for k in (1, 2)]
        cells = []
        for b in BUDGETS:
            out = os.path.join(tmp, f"{scene}_{b}.exr")
            subprocess.run([cli, os.path.join(cache, f"gpt_feature_{b}s.exr"), "-o", out,
                            "--norm", "feature", *args.extra.split()], check=True,
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            feature = M.rel_mse_denoised(R.rgb(out, ""), *refs)
            l1 = M.rel_mse_denoised(R.rgb(os.path.join(cache, f"gpt_{b}s_l1.exr"), ""), *refs)
            cells.append(f"{b:2d} s {feature:.3e} L1/F {l1 / feature:5.2f}")
            logs.append(np.log(l1 / feature))
        print(f"{scene:16s} " + "  ".join(cells), flush=True)
    print(f"geometric mean L1/F {np.exp(np.mean(logs)):.3f}")


if __name__ == "__main__":
    main()
