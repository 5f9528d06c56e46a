#!/usr/bin/python3
"""The benchmark report: GDPT against Cycles at equal time on the scenes of bench/scenes.

    python3 bench/report/run.py --build BUILD [--quick] [--scenes a,b] [--budgets 5,10]
                                [--ref-seconds S] [--res WxH] [--out-doc docs/benchmarks.md]

For each scene: builds its .blend (bench/scenes/build.py), renders each method's own converged
reference as two independent halves (cached in bench/results/cache/), then for every wall-clock
budget renders Cycles (defaults; unbiased), GDPT PT and GDPT G-PT, solves the G-PT passes with
gdpt-reconstruct (L2, L1, weighted; the solve's time is added to the render's), and measures
relMSE (against the method's own reference, the reference's noise subtracted) and SSIM. Writes
bench/results/<scene>.json, the plots and crops under docs/benchmarks/, and docs/benchmarks.md.
"""
import argparse
import datetime
import json
import os
import platform
import re
import shutil
import subprocess
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(ROOT, "tests", "blender"))
import exr  # noqa: E402
import metrics as M  # noqa: E402

SCENES = ["cornell_panel", "interior", "glossy", "glass_caustics", "difficult_light", "outdoor",
          "instances"]
# Rendered methods and the curves they give (G-PT gives one curve per reconstruction).
# gpt_feature: G-PT with the Feature reconstruction solved in the render (its feature passes
# cost render time, so it is a render of its own, as an artist picking Feature gets it).
RENDERED = ["cycles_default", "cycles_unbiased", "pt", "gpt", "gpt_feature"]
CURVES = {"cycles_default": "Cycles (defaults)", "cycles_unbiased": "Cycles (unbiased)",
          "pt": "GDPT PT", "gpt_l2": "GDPT G-PT + L2", "gpt_l1": "GDPT G-PT + L1",
          "gpt_weighted": "GDPT G-PT + weighted", "gpt_feature": "GDPT G-PT + feature"}
SOLVES = ["l2", "l1", "weighted"]
# Each curve's reference: Cycles' settings are biased differently, so each is measured against
# its own converged image; every GDPT curve against GDPT PT's.
REFERENCE_OF = {"cycles_default": "cycles_default", "cycles_unbiased": "cycles_unbiased",
                "pt": "pt", "gpt_l2": "pt", "gpt_l1": "pt", "gpt_weighted": "pt",
                "gpt_feature": "pt"}
GPT_CURVES = ("gpt_l2", "gpt_l1", "gpt_weighted", "gpt_feature")
# Cross-engine references are compared on 4x4 block means (the engines' pixel filters need not
# match sample for sample), their noise subtracted; above this relMSE the scene's comparison is void.
CROSS_BLOCK, CROSS_VOID = 4, 0.01


class Blender:
    """Runs bench scripts in headless Blender with the add-on staged from a build."""

    def __init__(self, build):
        self.build = build
        self.scripts = tempfile.mkdtemp(prefix="gdpt-bench-")
        subprocess.run(["bash", os.path.join(ROOT, "tests", "blender", "stage_addon.sh"), ROOT,
                        build, self.scripts], check=True, stdout=subprocess.DEVNULL)

    def run(self, script, *args):
        env = dict(os.environ, BLENDER_USER_SCRIPTS=self.scripts)
        cmd = ["blender", "-b", "--factory-startup", "--addons", "gdpt", "--python-exit-code", "1",
               "--python", script, "--", *map(str, args)]
        p = subprocess.run(cmd, env=env, capture_output=True, text=True)
        if p.returncode != 0:
            raise RuntimeError(f"{' '.join(cmd)} failed:\n{p.stdout[-3000:]}\n{p.stderr[-2000:]}")
        return p.stdout

    def close(self):
        shutil.rmtree(self.scripts, ignore_errors=True)


def samples_reached(log):
    """The largest 'Sample N/M' of Blender's progress lines (GDPT's finished line wins)."""
    done = re.findall(r"^GDPT: view layer .* finished: (\d+)/", log, re.M)
    if done:
        return int(done[-1])
    counts = [int(n) for n in re.findall(r"Sample (\d+)/\d+", log)]
    return max(counts) if counts else 0


def rendered_scenes_parser(out_name):
    """The options the scripts that render the report's scenes again share (bench/reconstruct/):
    --build, --scenes, --cache (the report's), --out (out/bench/<out_name>) and --resolve."""
    p = argparse.ArgumentParser()
    p.add_argument("--build", default="build")
    p.add_argument("--scenes", default=",".join(SCENES))
    p.add_argument("--cache", default=os.path.join(ROOT, "bench", "results", "cache"))
    p.add_argument("--out", default=os.path.join(ROOT, "out", "bench", out_name))
    p.add_argument("--resolve", action="store_true",
                   help="solve the renders already in --out again instead of rendering")
    return p


def update_scene_results(name, entries, **header):
    """Writes bench/results/<name> as {**header, "scenes": {scene: entry}}, keeping the scenes of
    the existing file that `entries` does not hold: a run over --scenes updates only those (each
    entry should say the commit it was measured at)."""
    path = os.path.join(ROOT, "bench", "results", name)
    scenes = {}
    if os.path.exists(path):
        with open(path) as f:
            old = json.load(f)
        scenes = old["scenes"] if isinstance(old, dict) else {r["scene"]: r for r in old}
    scenes.update(entries)
    with open(path, "w") as f:
        json.dump({**header, "scenes": {s: scenes[s] for s in SCENES if s in scenes}}, f, indent=1)


def render(blender, blend, method, out, seconds=0.0, samples=0, seed=1, adaptive=0.0,
           adaptive_min=0, shadow_caustics=None, filter_glossy=None):
    args = [blend, method, out] + (["--seconds", seconds] if seconds else ["--samples", samples])
    if shadow_caustics:
        args += ["--shadow-caustics", shadow_caustics]
    if filter_glossy is not None:
        args += ["--filter-glossy", filter_glossy]
    if adaptive:
        args += ["--adaptive", adaptive, "--adaptive-min", adaptive_min]
    log = blender.run(os.path.join(HERE, "render_one.py"), *args, "--seed", seed)
    line = next(ln for ln in log.splitlines() if ln.startswith("BENCH "))
    info = json.loads(line[6:])
    expected = "GDPT" if method in ("pt", "gpt", "gpt_feature") else "CYCLES"
    if info["engine"] != expected:
        raise RuntimeError(f"{method} rendered with {info['engine']}, not {expected}")
    info["samples"] = samples_reached(log)
    return info


def solve(build, exr_in, norm, out):
    """gdpt-reconstruct on a G-PT render; returns (image, seconds)."""
    cli = os.path.join(build, "reconstruct", "gdpt-reconstruct")
    t0 = time.perf_counter()
    subprocess.run([cli, exr_in, "-o", out, "--norm", norm], check=True,
                   stdout=subprocess.DEVNULL)
    return rgb(out, ""), time.perf_counter() - t0


def rgb(path, prefix="ViewLayer.Combined."):
    return exr.rgb(exr.read_exr(path), prefix)[..., :3].astype(np.float64)


def pass_mean(path, name):
    ch = exr.read_exr(path)
    key = next((k for k in ch if k.startswith(f"ViewLayer.{name}.")), None)
    return float(np.mean(ch[key])) if key else None


def reference_paths(cache, seconds):
    """{method: (half 1's path, half 2's path)} of the references in a scene's cache."""
    return {m: tuple(os.path.join(cache, f"ref_{m}_{seed}_{int(seconds)}s.exr") for seed in (1, 2))
            for m in ("cycles_default", "cycles_unbiased", "pt")}


def references(blender, build, blend, cache, seconds, log):
    """{method: (half a, half b)}, each half `seconds` long with its own seed, cached."""
    refs = {}
    for method, paths in reference_paths(cache, seconds).items():
        halves = []
        for seed, path in zip((1, 2), paths):
            if not os.path.exists(path):
                info = render(blender, blend, method, path + ".tmp.exr", seconds=seconds,
                              seed=1000 + seed)
                os.replace(path + ".tmp.exr", path)
                log(f"  reference {method} half {seed}: {info['samples']} samples")
            halves.append(rgb(path))
        refs[method] = tuple(halves)
    return refs


def cross_engine(result, refs):
    """How far GDPT PT's converged image is from each Cycles reference, and that figure's
    standard error (its noise), into `result`."""
    for key, f in (("cross_engine_relmse", M.rel_mse_between),
                   ("cross_engine_relmse_se", M.rel_mse_between_se)):
        result[key] = {f"pt~{m}": f(refs["pt"], refs[m], CROSS_BLOCK)
                       for m in ("cycles_unbiased", "cycles_default")}


def cached_references(cache, seconds):
    """The references of a finished run from its cache, or None when any is missing."""
    paths = reference_paths(cache, seconds)
    if not all(os.path.exists(p) for ps in paths.values() for p in ps):
        return None
    return {m: tuple(rgb(p) for p in ps) for m, ps in paths.items()}


def measure_scene(name, args, blender, log):
    cache = os.path.join(args.cache, f"{name}_{args.res}")
    os.makedirs(cache, exist_ok=True)
    blend = os.path.join(cache, f"{name}.blend")
    if not os.path.exists(blend):
        blender.run(os.path.join(ROOT, "bench", "scenes", "build.py"), name, blend, args.res)
    refs = references(blender, args.build, blend, cache, args.ref_seconds, log)
    ref = {m: 0.5 * (a + b) for m, (a, b) in refs.items()}
    result = {"scene": name, "resolution": args.res, "budgets": args.budgets,
              "reference_seconds_per_half": args.ref_seconds, "curves": {c: [] for c in CURVES}}
    cross_engine(result, refs)
    result["void"] = result["cross_engine_relmse"]["pt~cycles_unbiased"] > CROSS_VOID
    result["predicted_improvement"] = M.gradient_energy_ratio(ref["pt"])
    crops = {}
    kept = kept_curves(name, args)
    for curve, points in kept.items():
        result["curves"][curve] = points
        path = os.path.join(cache, f"{curve}_{args.crop_budget}s.exr")
        if not os.path.exists(path):  # a new cache: render the kept curve's crop image again
            render(blender, blend, curve, path, seconds=args.crop_budget, seed=7)
        crops[curve] = rgb(path)
    for budget in args.budgets:
        for method in RENDERED:  # interleaved: every method once per budget, in turn
            if method in kept:
                continue
            path = os.path.join(cache, f"{method}_{budget}s.exr")
            info = render(blender, blend, method, path, seconds=budget, seed=7)
            images = {}
            if method == "gpt":
                info["shift_failures"] = pass_mean(path, "Shift Failures")
                for norm in SOLVES:
                    img, secs = solve(args.build, path, norm, path[:-4] + f"_{norm}.exr")
                    images[f"gpt_{norm}"] = (img, info["seconds"] + secs, secs)
            else:
                images[method] = (rgb(path), info["seconds"], 0.0)
            for curve, (img, secs, solve_secs) in images.items():
                r = REFERENCE_OF[curve]
                point = {"budget": budget, "seconds": secs, "solve_seconds": solve_secs,
                         "samples": info["samples"], "relmse": M.rel_mse(img, ref[r]),
                         "relmse_denoised": M.rel_mse_denoised(img, *refs[r]),
                         "ssim": M.ssim(img, ref[r])}
                if "shift_failures" in info:
                    point["shift_failures"] = info["shift_failures"]
                result["curves"][curve].append(point)
                if budget == args.crop_budget:
                    crops[curve] = img
                log(f"  {budget:>4} s {CURVES[curve]:24s} {secs:6.1f} s {info['samples']:6d} spp "
                    f"relMSE {point['relmse_denoised']:.3e} SSIM {point['ssim']:.3f}")
    crops["reference"] = ref["pt"]
    summarise(result)
    return result, crops


def kept_curves(name, args):
    """{curve: points} of the --keep methods, taken from the scene's previous result file.

    Only Cycles' curves may be kept: Cycles does not change with GDPT's code, so a quiet earlier
    run of it on the same machine, Blender and budgets stands for a new one."""
    if not args.keep:
        return {}
    with open(os.path.join(args.results, f"{name}.json")) as f:
        old = json.load(f)
    if not set(args.budgets) <= set(old["budgets"]) or old["resolution"] != args.res:
        sys.exit(f"run.py: --keep needs budgets among the previous run's and its resolution "
                 f"for {name} ({old['budgets']}, {old['resolution']})")
    args.kept_from = old["meta"].get("kept_from") or {k: old["meta"][k] for k in ("commit", "date")}
    return {m: [p for p in old["curves"][m] if p["budget"] in args.budgets] for m in args.keep}


def summarise(result):
    """Equal-time ratios at 10 s and 40 s, the achieved G-PT improvement over PT, PT costs."""
    def at(curve, t):
        pts = result["curves"].get(curve, [])
        e = M.at_time([(p["seconds"], p["relmse_denoised"]) for p in pts], t)
        # A render that ended well before its budget (Cycles' adaptive sampling at its noise
        # threshold) gives the same image at any later time; so does one whose budget was t.
        last = max(pts, key=lambda p: p["seconds"], default=None)
        if e is None and last and t > last["seconds"] and (last["seconds"] < 0.9 * last["budget"]
                                                           or last["budget"] >= t):
            e = last["relmse_denoised"] if last["relmse_denoised"] > 0 else None
        return e

    result["equal_time"] = {}
    for t in (10, 40):
        row = {c: at(c, t) for c in CURVES}
        row["improvement_over_cycles_default"] = {
            c: row["cycles_default"] / row[c] if row["cycles_default"] and row[c] else None
            for c in ("pt",) + GPT_CURVES}
        row["achieved_gpt_l2_over_pt"] = (row["pt"] / row["gpt_l2"]
                                          if row["pt"] and row["gpt_l2"] else None)
        row["feature_over_l1"] = (row["gpt_l1"] / row["gpt_feature"]
                                  if row["gpt_l1"] and row["gpt_feature"] else None)
        result["equal_time"][str(t)] = row
    pt, gpt = result["curves"]["pt"], result["curves"]["gpt_l2"]
    result["gpt_cost_per_sample_over_pt"] = float(np.median(
        [(g["seconds"] - g["solve_seconds"]) / max(g["samples"], 1) /
         (p["seconds"] / max(p["samples"], 1)) for p, g in zip(pt, gpt)]))
    result["solve_time_share"] = {
        n: float(np.median([p["solve_seconds"] / p["seconds"] for p in result["curves"][f"gpt_{n}"]]))
        for n in SOLVES}


def plot(result, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(5.5, 4))
    for curve, label in CURVES.items():
        pts = [(p["seconds"], p["relmse_denoised"]) for p in result["curves"].get(curve, [])
               if p["relmse_denoised"] > 0]
        if pts:
            ax.loglog(*zip(*pts), marker="o", label=label)
    ax.set_xlabel("wall-clock seconds (whole render call + solve)")
    ax.set_ylabel("relMSE against own reference")
    ax.set_title(result["scene"])
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def save_crops(crops, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    order = [("cycles_default", "Cycles"), ("pt", "GDPT PT"), ("gpt_l1", "G-PT + L1"),
             ("reference", "reference")]
    fig, axes = plt.subplots(1, len(order), figsize=(3 * len(order), 2.6))
    for ax, (key, label) in zip(axes, order):
        img = crops.get(key)
        if img is not None:
            h, w = img.shape[:2]
            crop = img[h // 4:3 * h // 4, w // 4:3 * w // 4]
            ax.imshow(M.display(crop)[::-1], interpolation="nearest")  # rows bottom-first
        ax.set_title(label, fontsize=9)
        ax.axis("off")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def fmt(v, spec=".2f", suffix="x"):
    return "-" if v is None else f"{v:{spec}}{suffix}"


def verdict(r):
    """Sentences on what decides the scene at 40 s, from the measured figures only."""
    e = r["equal_time"]["40"]
    out = []
    cd, cu = e.get("cycles_default"), e.get("cycles_unbiased")
    if cd and cu and cu / cd >= 2:
        out.append(f"Cycles' defaults reach a {cu / cd:.1f}x lower error than its unbiased "
                   "setting at 40 s: their bias (Filter Glossy, clamping), measured against "
                   "their own reference, decides this scene.")
    pt = e.get("pt")
    if pt and cu and pt > 2 * cu:
        def samples(curve):
            return next((p["samples"] for p in r["curves"][curve] if p["budget"] == 40), None)
        ps, cs = samples("pt"), samples("cycles_unbiased")
        where = ("per sample, not in speed" if ps and cs and ps >= 0.8 * cs
                 else "in samples per second")
        out.append(f"GDPT's own path tracer is {pt / cu:.1f}x behind Cycles' unbiased setting at "
                   f"40 s ({ps} against {cs} samples at the 40 s budget): it loses {where}.")
    gpts = {c: e.get(c) for c in GPT_CURVES if e.get(c)}
    if not gpts or not cd:
        return out
    best = min(gpts, key=gpts.get)
    name = CURVES[best]
    if gpts[best] > cd:
        fails = [p.get("shift_failures") for p in r["curves"]["gpt_l2"]]
        why = [f"a G-PT sample costs {r['gpt_cost_per_sample_over_pt']:.2f}x a PT sample"]
        if fails and fails[-1] is not None:
            why.append(f"{fails[-1]:.1%} of shifts fail")
        share = r["solve_time_share"].get(best.split("_", 1)[1])
        if share is not None:
            why.append(f"the solve takes {share:.1%} of the time")
        out.append(f"**G-PT loses here**: at 40 s its best curve ({name}) has a "
                   f"{gpts[best] / cd:.2f}x higher error than Cycles' defaults ("
                   + "; ".join(why) + ").")
    else:
        out.append(f"At 40 s {name} has a {cd / gpts[best]:.2f}x lower error than Cycles' "
                   "defaults.")
    if e.get("pt") and gpts[best] > e["pt"]:
        out.append(f"Gradient sampling does not pay on this scene: GDPT's own PT is "
                   f"{gpts[best] / e['pt']:.2f}x better than {name} at 40 s.")
    return out


def write_doc(results, meta, path, figures, results_dir):
    lines = [
        "# Benchmarks: GDPT against Cycles at equal time",
        "",
        f"Generated by `{meta['command']}` at commit {meta['commit']} on {meta['date']}, "
        f"{meta['machine']}"
        + (f" (page and ratios rewritten from its JSON by `run.py --doc-only` at commit "
           f"{meta['page_commit']})" if meta.get("page_commit") else "")
        + (f"; the Feature curve's images solved again from that run's renders by the Feature "
           f"reconstruction of commit {meta['feature_resolved_at']} (`run.py --doc-only "
           "--resolve-feature`: same passes, render times and samples)"
           if meta.get("feature_resolved_at") else "")
        + ". Every figure below comes from `bench/results/<scene>.json` of that "
        "run; rerun the command to regenerate this page."
        + (f" Curves of {', '.join(meta['kept'])} are those of the run at commit "
           f"{meta['kept_from']['commit']} on {meta['kept_from']['date']} (same machine, Blender "
           "and budgets; `run.py --keep`): Cycles does not depend on GDPT's code, but the host's "
           "speed may differ between the two runs and that enters the equal-time ratios."
           if meta.get("kept") else ""),
        "",
        "relMSE is measured against each method's own converged reference (two independent "
        f"halves of {results[0]['reference_seconds_per_half']:g} s each, whose noise is "
        "subtracted); times are whole Blender render calls (export, "
        "render, write) plus, for G-PT, the `gdpt-reconstruct` solve. Cycles' defaults include "
        "Filter Glossy 1.0 and indirect clamping at 10 (biased, less noise) and adaptive sampling "
        "(which may stop before the budget: its last image then stands for every later time); "
        "\"unbiased\" sets the first two to 0 and samples "
        "every pixel for the whole budget. Denoising is off: Debian's Blender has no "
        "OpenImageDenoise.",
        "",
        "## Summary: relMSE improvement over Cycles at equal time",
        "",
    ]
    feature = any(r["curves"].get("gpt_feature") for r in results)

    def best_over_unbiased(e):
        gpts = [e[c] for c in GPT_CURVES if e.get(c)]
        return e["cycles_unbiased"] / min(gpts) if gpts and e.get("cycles_unbiased") else None

    # (header, cell of a result) per column; ratios over Cycles (defaults) unless named.
    columns = [
        ("refs agree (relMSE PT~Cycles, ± its noise)", lambda r: (
            f"{r['cross_engine_relmse']['pt~cycles_unbiased']:.1e}"
            + (f" ± {r['cross_engine_relmse_se']['pt~cycles_unbiased']:.0e}"
               if "cross_engine_relmse_se" in r else "") + (" (void)" if r["void"] else ""))),
        ("PT 10 s", lambda r: fmt(r["equal_time"]["10"]["improvement_over_cycles_default"]["pt"])),
        ("G-PT+L1 10 s", lambda r: fmt(
            r["equal_time"]["10"]["improvement_over_cycles_default"]["gpt_l1"])),
        ("G-PT+L2 40 s", lambda r: fmt(
            r["equal_time"]["40"]["improvement_over_cycles_default"]["gpt_l2"])),
        ("G-PT+L1 40 s", lambda r: fmt(
            r["equal_time"]["40"]["improvement_over_cycles_default"]["gpt_l1"])),
    ]
    if feature:
        columns += [
            ("G-PT+feature 40 s", lambda r: fmt(
                r["equal_time"]["40"]["improvement_over_cycles_default"].get("gpt_feature"))),
            ("feature over L1 (40 s)", lambda r: fmt(r["equal_time"]["40"].get("feature_over_l1")))]
    columns += [
        ("best G-PT over Cycles unbiased (40 s)", lambda r: fmt(best_over_unbiased(
            r["equal_time"]["40"]))),
        ("predicted / achieved G-PT over PT (40 s)", lambda r: (
            f"{fmt(r['predicted_improvement'], '.1f')} / "
            f"{fmt(r['equal_time']['40']['achieved_gpt_l2_over_pt'])}")),
    ]
    lines += ["| scene | " + " | ".join(h for h, _ in columns) + " |",
              "| --- |" + " --- |" * len(columns)]
    for r in results:
        lines.append(f"| {r['scene']} | " + " | ".join(cell(r) for _, cell in columns) + " |")
    lines += ["", "Ratios are Cycles' relMSE over GDPT's at the same time, against Cycles with its "
              "defaults unless the column names the unbiased setting; above 1x GDPT has the "
              "lower error; \"-\" means the budget range did not reach that time. \"refs agree\" is "
              "the relMSE between GDPT PT's and Cycles unbiased's references on 4x4 blocks with both "
              "references' noise subtracted, ± its standard error: 0 within a few of those where the "
              "engines agree, and a scene above 0.01 is marked void; the known causes of values "
              "further from 0 are in "
              "docs/lights.md (\"Where the references differ\").", ""]
    lines += targets_section(results, results_dir)
    for r in results:
        lines += [f"## {r['scene']}", ""]
        if r["void"]:
            lines += ["**The engines' references disagree on this scene (relMSE "
                      f"{r['cross_engine_relmse']['pt~cycles_unbiased']:.2e} on 4x4 blocks): the "
                      "comparison is void until the difference is explained.**", ""]
        own = r.get("meta", meta)
        if (own["commit"], own["date"]) != (meta["commit"], meta["date"]):
            lines += [f"This scene's curves come from a later run, `{own['command']}` at commit "
                      f"{own['commit']} on {own['date']} (every method rendered again, "
                      "references included; ratios against the other scenes' columns may include "
                      "the host's speed between the two runs).", ""]
        lines += [f"![relMSE against time]({figures[r['scene']][0]})", "",
                  f"![equal-time crops at {meta['crop_budget']} s]({figures[r['scene']][1]})", "",
                  "| method | " + " | ".join(f"{b} s" for b in r["budgets"]) + " |",
                  "| --- |" + " --- |" * len(r["budgets"])]
        for curve, label in CURVES.items():
            cells = [f"{p['relmse_denoised']:.2e} ({p['samples']} spp, SSIM {p['ssim']:.3f})"
                     for p in r["curves"].get(curve, [])]
            if not cells:
                continue  # a curve this run did not measure
            lines.append(f"| {label} | " + " | ".join(cells) + " |")
        fails = [p.get("shift_failures") for p in r["curves"]["gpt_l2"]]
        lines += ["", f"G-PT cost per sample: {r['gpt_cost_per_sample_over_pt']:.2f}x PT's; "
                  f"shift failures: {fmt(fails[-1], '.1%', '') if fails else '-'} of shifts; "
                  "reconstruction share of the time: " +
                  ", ".join(f"{n.upper()} {v:.1%}" for n, v in r["solve_time_share"].items()) +
                  f". Predicted improvement of gradient sampling (||F||^2 / ||G||^2 of the "
                  f"reference): {r['predicted_improvement']:.1f}x.", ""]
        lines += [" ".join(verdict(r)), ""] if verdict(r) else []
    with open(path, "w") as f:
        f.write("\n".join(lines))


# The Feature reconstruction's targets: its gains on these scenes, and what other benchmarks
# measure (their results files, when present): the demo's speckles (bench/demo/speckles.py, with
# Filter Glossy 0 and with the demo's own 1.0) and
# the reconstruction's time at 1920x1080 (bench_reconstruct --json).
FEATURE_OVER_L1, OVER_CYCLES, INTERIORS = 2.0, 10.0, ("cornell_panel", "interior")
FEATURE_SECONDS_1080P, L1_SECONDS_1080P, L1_OBJECTIVE_TOLERANCE = 5.0, 2.0, 1e-3


def read_result(results_dir, name):
    path = os.path.join(results_dir, name)
    if not os.path.exists(path):
        return None
    with open(path) as f:
        return json.load(f)


def met(ok):
    return "met" if ok else "**not met**"


def scene_targets(results):
    """Rows of the targets table measured on this page's scenes."""
    rows = []
    ratios = {r["scene"]: {t: r["equal_time"][t].get("feature_over_l1") for t in ("10", "40")}
              for r in results}
    at40 = {s: v["40"] for s, v in ratios.items() if v["40"]}
    if at40:
        every = [(v, s, t) for s, row in ratios.items() for t, v in row.items() if v]
        low = min(every)
        wins = [s for s, v in at40.items() if v >= FEATURE_OVER_L1]
        rows.append((f"Feature at least {FEATURE_OVER_L1:g}x lower relMSE than G-PT + L1 at equal "
                     "time on most scenes, never higher",
                     f"at 40 s {FEATURE_OVER_L1:g}x or more on {len(wins)} of {len(at40)} "
                     f"scenes ({', '.join(f'{s} {v:.2f}x' for s, v in at40.items())}); the "
                     f"lowest at 10 and 40 s {low[0]:.2f}x ({low[1]}, {low[2]} s)",
                     met(2 * len(wins) > len(at40) and low[0] >= 1.0), "the scenes below"))
    cells = [(r["scene"], r["equal_time"]["40"]["improvement_over_cycles_default"].get(
        "gpt_feature"), r["equal_time"]["40"]) for r in results if r["scene"] in INTERIORS]
    cells = [c for c in cells if c[1]]
    if cells:
        unbiased = [e["cycles_unbiased"] / e["gpt_feature"] for _, _, e in cells
                    if e.get("cycles_unbiased") and e.get("gpt_feature")]
        rows.append((f"Feature at least {OVER_CYCLES:g}x lower relMSE than Cycles without "
                     "denoising on the diffuse interiors",
                     "at 40 s " + ", ".join(f"{s} {fmt(v)}" for s, v, _ in cells)
                     + " against Cycles' defaults ("
                     + ", ".join(f"{v:.2f}x" for v in unbiased) + " against its unbiased setting)",
                     met(all(v and v >= OVER_CYCLES for _, v, _ in cells)), "the scenes below"))
    return rows


def speckle_target(d):
    """The demo's speckles (bench/results/demo_speckles.json) as a targets row."""
    flagged = [p for row in d["per_seed"]["feature"] for p in row.get("speckle_pixels", [])]
    where = ""
    if flagged:
        truth = [p["reference_over_median"] for p in flagged]
        over = [p["over_median"] / p["reference_over_median"] for p in flagged]
        where = (f"; the Feature ones where the reference is {min(truth):.2f}-{max(truth):.2f}x "
                 f"its median, at {min(over):.2f}-{max(over):.2f}x the reference")
    per = {m: d[m] for m in ("primal", "l1", "feature")}
    blur = d.get("filter_glossy", 0.0)
    setting = (f"the demo's own Filter Glossy {blur:g}" if blur else "Filter Glossy 0, unbiased")
    return ("No isolated bright speckles on the demo at its default samples (pixels over "
            f"{d['speckle_ratio']:g}x the reference's 5x5 median; {setting})",
            f"per render at {d['samples']} samples: primal {per['primal']['speckles_mean']:.1f}, "
            f"L1 {per['l1']['speckles_mean']:.1f}, Feature {per['feature']['speckles_mean']:.2f}; "
            "isolated (the reference under 1.7x its median there) "
            f"{per['primal']['isolated_mean']:.1f}, {per['l1']['isolated_mean']:.1f}, "
            f"{per['feature']['isolated_mean']:.2f}" + where,
            met(per["feature"]["isolated_mean"] == 0),
            f"`bench/demo/speckles.py`, {d['seeds']} seeds, commit {d['commit']}")


def time_targets(d):
    """The 1920x1080 times (bench/results/reconstruct.json) as targets rows."""
    run = next((r for r in d["runs"] if r["threads"] == 2), None)
    if run is None or (d["width"], d["height"]) != (1920, 1080):
        return []
    source = f"`bench_reconstruct --json`, commit {d.get('commit', '?')}"
    rows = [(f"Feature at 1920x1080 under {FEATURE_SECONDS_1080P:g} s on 2 cores",
             f"{run['feature_seconds']:.2f} s = solves {run['feature_solves_seconds']:.2f} s "
             f"+ filters {run['feature_filters_seconds']:.2f} s",
             met(run["feature_seconds"] < FEATURE_SECONDS_1080P), source)]
    if run["l1_seconds"] >= 0:
        rows.append((f"L1 at 1920x1080 under {L1_SECONDS_1080P:g} s on 2 cores, objective within "
                     f"{L1_OBJECTIVE_TOLERANCE:.1%} of the reference scheme's",
                     f"{run['l1_seconds']:.2f} s, objective {run['l1_objective_vs_l1d']:+.4%} "
                     "against L1D's",
                     met(run["l1_seconds"] < L1_SECONDS_1080P
                         and run["l1_objective_vs_l1d"] <= L1_OBJECTIVE_TOLERANCE), source))
    return rows


def targets_section(results, results_dir):
    rows = scene_targets(results)
    for name in ("demo_speckles.json", "demo_speckles_filter_glossy_1.json"):
        speckles = read_result(results_dir, name)
        rows += [speckle_target(speckles)] if speckles else []
    timing = read_result(results_dir, "reconstruct.json")
    rows += time_targets(timing) if timing else []
    if not rows:
        return []
    return (["## The Feature reconstruction's targets", "",
             "From this page's scenes and the results of the other benchmarks `make bench` runs "
             "(docs/reconstruct.md explains each measurement).", "",
             "| target | measured | status | source |", "| --- | --- | --- | --- |"]
            + [f"| {t} | {m} | {ok} | {src} |" for t, m, ok, src in rows] + [""])


def git(*args):
    return subprocess.run(["git", "-C", ROOT, *args], capture_output=True, text=True).stdout.strip()


def resolve_feature(name, args, result):
    """The Feature curve's images solved again from the run's cached G-PT + Feature renders by
    this build's `gdpt-reconstruct --norm feature` (the function the render calls, on the same
    passes); the render's time and samples are kept: the reconstruction's cost is unchanged."""
    cache = os.path.join(args.cache, f"{name}_{result['resolution']}")
    refs = tuple(rgb(os.path.join(cache, f"ref_pt_{seed}_{int(result['reference_seconds_per_half'])}s.exr"))
                 for seed in (1, 2))
    ref = 0.5 * (refs[0] + refs[1])
    for point in result["curves"]["gpt_feature"]:
        path = os.path.join(cache, f"gpt_feature_{point['budget']}s.exr")
        img, _ = solve(args.build, path, "feature", path[:-4] + "_resolved.exr")
        point.update(relmse=M.rel_mse(img, ref), relmse_denoised=M.rel_mse_denoised(img, *refs),
                     ssim=M.ssim(img, ref))
    result["meta"]["feature_resolved_at"] = git("rev-parse", "--short", "HEAD")


def rewrite_doc(args, fig_dir, doc_dir):
    """The page and plots again from a finished run's JSON (its own commit and date kept)."""
    results, figures = [], {}
    for name in args.scenes:
        with open(os.path.join(args.results, f"{name}.json")) as f:
            result = json.load(f)
        if args.resolve_feature:
            resolve_feature(name, args, result)
        if "cross_engine_relmse_se" not in result:  # runs before it was recorded
            refs = cached_references(os.path.join(args.cache, f"{name}_{result['resolution']}"),
                                     result["reference_seconds_per_half"])
            if refs:
                cross_engine(result, refs)
        summarise(result)  # the derived ratios again; the measured points stay as they are
        result["meta"]["page_commit"] = git("rev-parse", "--short", "HEAD")
        with open(os.path.join(args.results, f"{name}.json"), "w") as f:
            json.dump(result, f, indent=1)
        plot(result, os.path.join(fig_dir, f"{name}_relmse.png"))
        rel = os.path.relpath(fig_dir, doc_dir)
        figures[name] = (f"{rel}/{name}_relmse.png", f"{rel}/{name}_crops.png")
        results.append(result)
    write_doc(results, results[0]["meta"], args.out_doc, figures, args.results)
    print(f"rewrote {args.out_doc} from {len(results)} result files in {args.results}")


def command_line(args, quick):
    """How the page says it was made: `make bench` unless budgets or scenes were chosen by hand."""
    build = os.path.relpath(os.path.abspath(args.build), ROOT)
    if args.budgets_given or args.scenes_given or build != "build":
        return ("bench/report/run.py" + (f" --build {build}" if build != "build" else "")
                + (f" --scenes {','.join(args.scenes)}" if args.scenes_given else "")
                + f" --budgets {','.join(map(str, args.budgets))}"
                + (f" --keep {','.join(args.keep)}" if args.keep else ""))
    return ("make bench" + (" QUICK=1" if quick else "")
            + (f" KEEP={','.join(args.keep)}" if args.keep else ""))


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--build", default=os.path.join(ROOT, "build"))
    p.add_argument("--quick", action="store_true", help="two scenes, short budgets, 160x120")
    p.add_argument("--scenes", help="comma-separated subset of " + ",".join(SCENES))
    p.add_argument("--budgets", help="comma-separated seconds (default 5,10,20,40,80)")
    p.add_argument("--ref-seconds", type=float, help="seconds per reference half (default 40)")
    p.add_argument("--resolve-feature", action="store_true",
                   help="with --doc-only: solve the Feature curve again from the cached renders")
    p.add_argument("--doc-only", action="store_true",
                   help="rewrite the page and plots from bench/results/<scene>.json, no rendering")
    p.add_argument("--res", help="WIDTHxHEIGHT (default 320x240)")
    p.add_argument("--keep", help="comma-separated Cycles methods whose curves are taken from the "
                   "previous bench/results/<scene>.json instead of rendered again "
                   "(cycles_default, cycles_unbiased); their renders must be in the cache")
    p.add_argument("--out-doc", default=os.path.join(ROOT, "docs", "benchmarks.md"))
    p.add_argument("--results", default=os.path.join(ROOT, "bench", "results"))
    p.add_argument("--cache", default=os.path.join(ROOT, "bench", "results", "cache"),
                   help="scenes, references and renders (references are reused)")
    args = p.parse_args()
    args.build = os.path.abspath(args.build)
    quick = args.quick
    args.budgets_given, args.scenes_given = bool(args.budgets), bool(args.scenes)
    args.keep = args.keep.split(",") if args.keep else []
    if any(m not in ("cycles_default", "cycles_unbiased") for m in args.keep):
        sys.exit("run.py: --keep takes only cycles_default and cycles_unbiased")
    args.scenes = (args.scenes or ("cornell_panel,interior" if quick else ",".join(SCENES))).split(",")
    args.budgets = [float(b) if "." in b else int(b) for b in
                    (args.budgets or ("2,4,8" if quick else "5,10,20,40,80")).split(",")]
    args.ref_seconds = args.ref_seconds or (20.0 if quick else 40.0)
    args.res = args.res or ("160x120" if quick else "320x240")
    args.crop_budget = 40 if 40 in args.budgets else args.budgets[-1]
    unknown = [s for s in args.scenes if s not in SCENES]
    if unknown:
        sys.exit(f"run.py: unknown scene(s) {', '.join(unknown)} (known: {', '.join(SCENES)})")
    doc_dir = os.path.dirname(os.path.abspath(args.out_doc))
    fig_dir = os.path.join(doc_dir, "benchmarks")
    os.makedirs(fig_dir, exist_ok=True)
    os.makedirs(args.results, exist_ok=True)
    meta = {"commit": git("rev-parse", "--short", "HEAD") + ("+dirty" if git("status", "--porcelain",
                                                                            "--untracked-files=no") else ""),
            "date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
            "machine": f"{platform.machine()}, {os.cpu_count()} cores",
            "command": command_line(args, quick), "crop_budget": args.crop_budget}
    if args.doc_only:
        return rewrite_doc(args, fig_dir, doc_dir)
    blender = Blender(args.build)
    results, figures = [], {}
    try:
        for name in args.scenes:
            print(f"scene {name}", flush=True)
            result, crops = measure_scene(name, args, blender, lambda s: print(s, flush=True))
            if args.keep:
                meta.update(kept=args.keep, kept_from=args.kept_from)
            result["meta"] = meta
            with open(os.path.join(args.results, f"{name}.json"), "w") as f:
                json.dump(result, f, indent=1)
            plot_path = os.path.join(fig_dir, f"{name}_relmse.png")
            crop_path = os.path.join(fig_dir, f"{name}_crops.png")
            plot(result, plot_path)
            save_crops(crops, crop_path)
            rel = os.path.relpath(fig_dir, doc_dir)
            figures[name] = (f"{rel}/{name}_relmse.png", f"{rel}/{name}_crops.png")
            results.append(result)
    finally:
        blender.close()
    write_doc(results, meta, args.out_doc, figures, args.results)
    print(f"wrote {args.out_doc} and {len(results)} result files in {args.results}")


if __name__ == "__main__":
    main()
