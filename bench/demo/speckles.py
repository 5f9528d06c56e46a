# The Feature reconstruction's target "no isolated bright speckles left on the demo at its default
# samples": the demo scene (blender_addon/demo/make_demo_scene.py) rendered by G-PT at the demo's
# sample count, reconstructed with L1 and with Feature (the demo's setting), against GDPT PT's
# converged image.
# A speckle is a pixel whose luminance is more than 4x the median of the reference's 5x5
# neighbourhood (that median floored at 1e-3, so black regions count only real light). Also
# relMSE (epsilon 0.01) against the reference, which decides which default the demo should use.
# Also what a render with the reference's sample count scores (each reference half against the
# other's medians) and, for each Feature speckle, its and the reference's ratio to the median.
# Also, over the seeds, how the Feature render's halves see their own error where the reference
# is a bright feature (over 1.7x its median): their (A - B)^2 / 4 over the true squared error of
# (A + B) / 2, and the correlation of the halves' errors (an estimate the halves understate there
# would let both halves' rare bright paths through as light), and how often both halves of one
# render have a firefly (over 4x the median) at the same pixel of a flat region (the reference
# within 0.7-1.3x its median) against halves of different seeds: more in one render would mean
# the halves, two segments of one sequence, draw rare paths together.
# Which speckles are isolated (the reference there under 1.7x its median: light the scene does
# not have there) and which sit on a bright feature of the reference; and, in the demo's view
# (Filmic, through OpenColorIO by oiiotool), how far each Feature speckle is from the reference in
# 8-bit display levels and how many pixels of the same render are farther; and per render the
# 99.9th percentile of every pixel's display distance.
#   /usr/bin/python3 bench/demo/speckles.py [--build build] [--ref-samples 2048] [--seeds 4]
#       [--samples N] [--filter-glossy F] [--reuse]
# --reuse takes the renders already in the folder (after a change that leaves the renders and the
# in-render reconstruction alone).
# Every render and the reference are made with Filter Glossy 0 (unbiased), or with --filter-glossy
# F (the demo's own setting is 1.0, Cycles' default, which blurs the sphere's glass after a
# diffuse bounce: the floor's caustic then reaches light samples at the roughened glass).
# Writes bench/results/demo_speckles.json (demo_speckles_<N>spp.json with --samples,
# demo_speckles[_<N>spp]_filter_glossy_<F>.json with --filter-glossy; their renders in
# out/bench/demo with the same suffix) and prints one line per reconstruction.
import argparse
import json
import os
import subprocess
import sys
import tempfile

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "bench", "report"))
import metrics as M  # noqa: E402
import run as R  # noqa: E402
import exr  # noqa: E402  (tests/blender, on the path run.py sets)

SPECKLE_RATIO, MEDIAN_FLOOR = 4.0, 1e-3
BRIGHT_FEATURE_RATIO = 1.7
DEMO_VIEW = ("sRGB", "Filmic")  # make_demo_scene.py's display and view transform
OCIO_CONFIG = os.environ.get("OCIO", "/usr/share/blender/datafiles/colormanagement/config.ocio")


def demo_samples(blender, blend):
    """The demo scene's own sample count (demo_samples.py inside Blender on `blend`)."""
    return int(blender.run(os.path.join(HERE, "demo_samples.py"),
                           blend).split("DEMO_SAMPLES ")[1].split()[0])


def suffix(samples=None, filter_glossy=0.0):
    """The names' suffix of a measurement other than the default (its results and renders)."""
    return (f"_{samples}spp" if samples else "") + (
        f"_filter_glossy_{filter_glossy:g}" if filter_glossy else "")


def results_path(samples=None, filter_glossy=0.0):
    """bench/results/demo_speckles<suffix>.json: what main() writes for that measurement."""
    return os.path.join(ROOT, "bench", "results",
                        f"demo_speckles{suffix(samples, filter_glossy)}.json")


def demo_study(name, parser=None):
    """What the demo studies share (shadow_caustics.py, speckle_paths.py, adaptive.py): their
    options (--build, --seeds and those `parser` already has), speckles.py's reference, their
    folder out/bench/<name> and a Blender with the add-on staged (the caller closes it)."""
    p = parser or argparse.ArgumentParser()
    p.add_argument("--build", default="build")
    p.add_argument("--seeds", type=int, default=4)
    args = p.parse_args()
    return args, Reference(), out_dir(name), R.Blender(args.build)


def out_dir(name):
    """out/bench/<name>, created."""
    path = os.path.join(ROOT, "out", "bench", name)
    os.makedirs(path, exist_ok=True)
    return path


def floored_median(ref):
    """The 5x5 median of `ref`'s luminance around each pixel, floored at MEDIAN_FLOOR."""
    padded = np.pad(M.luminance(ref), 2, mode="edge")
    return np.maximum(np.median(sliding_window_view(padded, (5, 5)), axis=(-2, -1)), MEDIAN_FLOOR)


def speckle_mask(img, median):
    """Pixels of `img` brighter than SPECKLE_RATIO x `median` (a reference's floored_median)."""
    return M.luminance(img) > SPECKLE_RATIO * median


def speckles(img, median):
    return int(np.count_nonzero(speckle_mask(img, median)))


def display_levels(paths, prefix="ViewLayer.Combined."):
    """The mean of the EXRs' RGB (scene linear) in the demo's view, in 8-bit levels (0-255)."""
    cmd = ["oiiotool"]
    for k, path in enumerate(paths):
        cmd += [path, "--ch", ",".join(f"{c}={prefix}{c}" for c in "RGB")]
        if k:
            cmd += ["--add"]
    if len(paths) > 1:
        cmd += ["--mulc", str(1.0 / len(paths))]
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "display.exr")
        cmd += ["--colorconfig", OCIO_CONFIG, "--ociodisplay:from=Linear", *DEMO_VIEW, "-d",
                "float", "-o", out]
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
        ch = exr.read_exr(out)
        return 255.0 * np.stack([ch[c] for c in "RGB"], axis=-1).astype(np.float64)


def isolated(img, ref, median):
    """Speckles of `img` where the reference is under BRIGHT_FEATURE_RATIO x its median."""
    flat = M.luminance(ref) < BRIGHT_FEATURE_RATIO * median
    return int(np.count_nonzero(speckle_mask(img, median) & flat))


class Reference:
    """The demo's converged reference (speckles.py's two halves in out/bench/demo) and what the
    other demo scripts score renders against."""

    def __init__(self):
        demo = os.path.join(ROOT, "out", "bench", "demo")
        self.paths = [os.path.join(demo, f"ref_{k}.exr") for k in (1, 2)]
        self.blend = os.path.join(demo, "demo.blend")
        if not all(os.path.exists(f) for f in self.paths + [self.blend]):
            sys.exit(f"run bench/demo/speckles.py first (needs {self.blend} and its references)")
        self.halves = [R.rgb(f) for f in self.paths]
        self.image = 0.5 * (self.halves[0] + self.halves[1])
        self.display = display_levels(self.paths)
        self.median = floored_median(self.image)

    def score(self, path):
        """Speckles, isolated speckles, relMSE and the display error's 99.9th percentile."""
        img = R.rgb(path)
        err = np.abs(display_levels([path]) - self.display).max(axis=-1)
        return {"speckles": speckles(img, self.median),
                "isolated": isolated(img, self.image, self.median),
                "relmse": M.rel_mse_denoised(img, *self.halves),
                "display_error_p999": float(np.percentile(err, 99.9))}


SCORE_KEYS = ("seconds", "speckles", "isolated", "relmse", "display_error_p999")


def summarise(result, rows, name_width, extra=()):
    """Per method in `rows` (lists of per-seed scores with "seconds"), the means of SCORE_KEYS
    and `extra` into `result`, one printed line each; writes nothing."""
    for name, r in rows.items():
        m = {k: float(np.mean([x[k] for x in r])) for k in SCORE_KEYS + tuple(extra)}
        result[name] = m
        more = "".join(f", {k} {m[k]:.1f}" for k in extra)
        print(f"{name:{name_width}s} {m['seconds']:.2f} s{more}, speckles {m['speckles']:.2f}, "
              f"isolated {m['isolated']:.2f}, relMSE {m['relmse']:.3e}, display p99.9 "
              f"{m['display_error_p999']:.1f}", flush=True)


def speckle_details(img, ref, median):
    """Each speckle of `img`: where, its and the reference's luminance over the median."""
    lum, lum_ref = M.luminance(img), M.luminance(ref)
    return [{"x": int(x), "y": int(y), "over_median": float(lum[y, x] / median[y, x]),
             "reference_over_median": float(lum_ref[y, x] / median[y, x])}
            for y, x in zip(*np.nonzero(speckle_mask(img, median)))]


def halves_estimate(halves_a, halves_b, ref, median):
    """Over the seeds, at the reference's bright features: the halves' (A - B)^2 / 4 over the
    true squared error of their mean, and the correlation of their errors (luminance)."""
    truth = M.luminance(ref)
    mask = truth > BRIGHT_FEATURE_RATIO * median
    a = np.array([M.luminance(x)[mask] for x in halves_a]) - truth[mask]
    b = np.array([M.luminance(x)[mask] for x in halves_b]) - truth[mask]
    return {"pixels": int(np.count_nonzero(mask)),
            "estimate_over_true": float(np.sum((a - b) ** 2 / 4) / np.sum(((a + b) / 2) ** 2)),
            "error_correlation": float(np.sum(a * b) / np.sqrt(np.sum(a * a) * np.sum(b * b)))}


def halves_fireflies(halves_a, halves_b, ref, median):
    """Pixels of flat regions where both halves are over SPECKLE_RATIO x the median: summed over
    the renders, and for halves of different seeds (mean over the seed pairings)."""
    lum = M.luminance(ref)
    flat = (lum > 0.7 * median) & (lum < 1.3 * median)
    fa = [speckle_mask(x, median) & flat for x in halves_a]
    fb = [speckle_mask(x, median) & flat for x in halves_b]
    n = len(fa)
    both = [sum(int(np.count_nonzero(fa[i] & fb[(i + k) % n])) for i in range(n))
            for k in range(n)]
    return {"flat_pixels": int(np.count_nonzero(flat)) * n,
            "one_half": sum(int(np.count_nonzero(x)) for x in fa + fb) / 2,
            "both_halves_same_render": both[0],
            "both_halves_different_seeds": float(np.mean(both[1:])) if n > 1 else None}


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--build", default="build")
    p.add_argument("--ref-samples", type=int, default=2048, help="per reference half")
    p.add_argument("--seeds", type=int, default=4, help="G-PT renders (seeds) to average over")
    p.add_argument("--samples", type=int, help="G-PT samples instead of the demo's own")
    p.add_argument("--out", help="renders' folder (default out/bench/demo[_<N>spp])")
    p.add_argument("--reuse", action="store_true", help="take the renders already in --out")
    p.add_argument("--filter-glossy", type=float, default=0.0,
                   help="Filter Glossy of every render, the reference's too (default 0: unbiased; "
                        "the demo's own is 1.0)")
    args = p.parse_args()
    args.out = args.out or os.path.join(ROOT, "out", "bench",
                                        "demo" + suffix(args.samples, args.filter_glossy))
    os.makedirs(args.out, exist_ok=True)
    blender = R.Blender(args.build)

    def render(blend, method, path, **kw):
        if not (args.reuse and os.path.exists(path)):
            R.render(blender, blend, method, path, filter_glossy=args.filter_glossy, **kw)

    try:
        blend = os.path.join(args.out, "demo.blend")
        if not (args.reuse and os.path.exists(blend)):
            blender.run(os.path.join(ROOT, "blender_addon", "demo", "make_demo_scene.py"), blend)
        samples = args.samples or demo_samples(blender, blend)
        halves = []
        for seed in (1, 2):
            path = os.path.join(args.out, f"ref_{seed}.exr")
            render(blend, "pt", path, samples=args.ref_samples, seed=1000 + seed)
            halves.append(R.rgb(path))
        ref = 0.5 * (halves[0] + halves[1])
        ref_display = display_levels([os.path.join(args.out, f"ref_{k}.exr") for k in (1, 2)])
        # What a render of the reference's own sample count scores: each half against the other.
        floor = 0.5 * (speckles(halves[0], floored_median(halves[1])) +
                       speckles(halves[1], floored_median(halves[0])))
        median = floored_median(ref)
        print(f"demo reference half ({args.ref_samples} spp) against the other half: speckles "
              f"{floor:.1f}", flush=True)
        rows = {"primal": [], "l1": [], "feature": []}
        feature_halves = ([], [])
        for seed in range(1, args.seeds + 1):
            raw = os.path.join(args.out, f"gpt_{seed}.exr")
            render(blend, "gpt", raw, samples=samples, seed=seed)
            l1, _ = R.solve(args.build, raw, "l1", raw[:-4] + "_l1.exr")
            feat = os.path.join(args.out, f"feature_{seed}.exr")
            render(blend, "gpt_feature", feat, samples=samples, seed=seed)
            # Reconstruction None: Combined is the primal plus emission.
            feature = R.rgb(feat)
            for half, name in zip(feature_halves, ("Primal A", "Primal B")):
                half.append(R.rgb(feat, f"ViewLayer.{name}."))
            display_errors = {}
            for name, img, path, prefix in (("primal", R.rgb(raw), raw, "ViewLayer.Combined."),
                                            ("l1", l1, raw[:-4] + "_l1.exr", ""),
                                            ("feature", feature, feat, "ViewLayer.Combined.")):
                err = np.abs(display_levels([path], prefix) - ref_display).max(axis=-1)
                display_errors[name] = err
                rows[name].append({"speckles": speckles(img, median),
                                   "isolated": isolated(img, ref, median),
                                   "relmse": M.rel_mse_denoised(img, *halves),
                                   "display_error_p999": float(np.percentile(err, 99.9))})
            details = speckle_details(feature, ref, median)
            display_error = display_errors["feature"]
            for d in details:
                e = display_error[d["y"], d["x"]]
                d["display_error_levels"] = float(e)
                d["pixels_farther_in_display"] = int(np.count_nonzero(display_error > e))
                print(f"  feature seed {seed} speckle ({d['x']}, {d['y']}): {d['over_median']:.2f}x "
                      f"the median, reference {d['reference_over_median']:.2f}x; in the demo's "
                      f"view {e:.1f} levels from the reference, "
                      f"{d['pixels_farther_in_display']} pixels farther", flush=True)
            rows["feature"][-1]["speckle_pixels"] = details
    finally:
        blender.close()
    result = {"samples": samples, "filter_glossy": args.filter_glossy,
              "reference_samples_per_half": args.ref_samples,
              "seeds": args.seeds, "speckle_ratio": SPECKLE_RATIO, "commit": R.git(
                  "rev-parse", "--short", "HEAD"),
              "pixels": int(ref.shape[0] * ref.shape[1]), "reference_half_speckles": floor,
              "per_seed": rows,
              "bright_features_halves": halves_estimate(*feature_halves, ref, median),
              "flat_region_fireflies": halves_fireflies(*feature_halves, ref, median)}
    for name, r in rows.items():
        s = [x["speckles"] for x in r]
        iso = [x["isolated"] for x in r]
        e = [x["relmse"] for x in r]
        p999 = [x["display_error_p999"] for x in r]
        result[name] = {"speckles_mean": float(np.mean(s)), "isolated_mean": float(np.mean(iso)),
                        "relmse_mean": float(np.mean(e)),
                        "display_error_p999_mean": float(np.mean(p999))}
        print(f"demo {samples} spp {name:8s} speckles {np.mean(s):7.1f} (per seed {s}), isolated "
              f"{np.mean(iso):.1f}, relMSE {np.mean(e):.3e}, display error's 99.9th percentile "
              f"{np.mean(p999):.1f} levels", flush=True)
    h = result["bright_features_halves"]
    print(f"Feature halves at the reference's {h['pixels']} bright-feature pixels: (A - B)^2 / 4 "
          f"over the true error {h['estimate_over_true']:.2f}, error correlation "
          f"{h['error_correlation']:.2f}", flush=True)
    f = result["flat_region_fireflies"]
    print(f"Feature halves' fireflies in flat regions ({f['flat_pixels']} pixels over the renders): "
          f"{f['one_half']:.1f} per half, in both halves {f['both_halves_same_render']} (one render) "
          f"against {f['both_halves_different_seeds']} (different seeds)", flush=True)
    with open(results_path(args.samples, args.filter_glossy), "w") as f:
        json.dump(result, f, indent=1)


if __name__ == "__main__":
    main()
