# The farm test's oracle (run with /usr/bin/python3, which has numpy): the merged EXR equals the
# single-machine render of all samples, channel by channel, within float rounding (the largest
# difference at most 1e-6 of the channel's largest value; Combined 1e-5: the Feature / L1 solves
# amplify rounding), and each part alone differs from it (the test is not comparing a render
# with itself).
#   python3 compare_exr.py MERGED.exr SINGLE.exr PART.exr...
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "blender"))
import exr  # noqa: E402


def worst(a, b):
    """The largest difference of each channel of `a` against `b`, relative to b's largest
    magnitude."""
    out = {}
    for name, ref in b.items():
        if name not in a:
            out[name] = float("inf")
            continue
        scale = float(np.max(np.abs(ref)))
        diff = float(np.max(np.abs(a[name].astype(np.float64) - ref)))
        out[name] = diff / scale if scale > 0 else diff
    return out


def main():
    merged_path, single_path, *parts = sys.argv[1:]
    merged, single = exr.read_exr(merged_path), exr.read_exr(single_path)
    failures = []
    if sorted(merged) != sorted(single):
        failures.append(f"channels differ: {sorted(set(merged) ^ set(single))}")
    for name, d in sorted(worst(merged, single).items()):
        limit = 1e-5 if ".Combined." in name else 1e-6
        print(f"  {name}: {d:.3g} (limit {limit:g})")
        if not d <= limit:
            failures.append(f"{name} differs by {d:.3g} of its scale (limit {limit:g})")
    for part in parts:
        d = worst(exr.read_exr(part), single)
        primal = max(v for k, v in d.items() if ".Primal." in k)
        print(f"  {os.path.basename(part)} alone: Primal differs by {primal:.3g}")
        if primal < 1e-3:
            failures.append(f"{part} alone equals the full render (Primal within {primal:.3g})")
    if failures:
        print("FAIL:\n  " + "\n  ".join(failures))
        sys.exit(1)
    print(f"ok: {os.path.basename(merged_path)} equals the single render of all samples "
          f"({len(single)} channels)")


main()
