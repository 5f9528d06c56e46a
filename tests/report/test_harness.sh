#!/usr/bin/env bash
# The benchmark report's harness end to end on one tiny scene at 1 s budgets: every method
# renders with its own engine, the JSON holds finite errors for every curve, the engines'
# references agree, and the page and its figures are written, with the table of the Feature
# reconstruction's targets from other benchmarks' results (stand-ins written here).
#   test_harness.sh <build-dir> <out-dir>
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
build=$1 out=$2
rm -rf "$out"
mkdir -p "$out/results"
# What other benchmarks would have measured, for the page's table of the Feature reconstruction's
# targets: the demo's speckles with Filter Glossy 0 (no isolated one: met) and with the demo's own
# 1.0 (an isolated one in one render of four: not met), a 1920x1080 Feature over 5 s (not met).
cat > "$out/results/demo_speckles.json" <<'JSON'
{"samples": 32, "seeds": 2, "speckle_ratio": 4.0, "commit": "abc1234",
 "per_seed": {"feature": [{"speckle_pixels": [{"over_median": 6.0, "reference_over_median": 3.0}]},
                          {"speckle_pixels": []}]},
 "primal": {"speckles_mean": 400.0, "isolated_mean": 390.0},
 "l1": {"speckles_mean": 40.0, "isolated_mean": 35.0},
 "feature": {"speckles_mean": 0.5, "isolated_mean": 0.0}}
JSON
cat > "$out/results/demo_speckles_filter_glossy_1.json" <<'JSON'
{"samples": 32, "seeds": 4, "speckle_ratio": 4.0, "commit": "abc1234", "filter_glossy": 1.0,
 "per_seed": {"feature": []},
 "primal": {"speckles_mean": 10.0, "isolated_mean": 8.0},
 "l1": {"speckles_mean": 3.0, "isolated_mean": 0.5},
 "feature": {"speckles_mean": 0.25, "isolated_mean": 0.25}}
JSON
cat > "$out/results/reconstruct.json" <<'JSON'
{"commit": "abc1234", "width": 1920, "height": 1080,
 "runs": [{"threads": 2, "l1_seconds": 1.5, "l1_objective_vs_l1d": -1e-5, "feature_seconds": 6.25,
           "feature_solves_seconds": 2.0, "feature_filters_seconds": 4.25,
           "feature_relmse_l1_over_feature": 10.0}]}
JSON
/usr/bin/python3 "$root/bench/report/run.py" --build "$build" --scenes cornell_panel \
  --budgets 1,2 --ref-seconds 3 --res 48x36 --results "$out/results" --cache "$out/cache" \
  --out-doc "$out/doc/benchmarks.md"
/usr/bin/python3 - "$out" <<'PY'
import json, math, os, sys
out = sys.argv[1]
r = json.load(open(os.path.join(out, "results", "cornell_panel.json")))
curves = ["cycles_default", "cycles_unbiased", "pt", "gpt_l2", "gpt_l1", "gpt_weighted",
          "gpt_feature"]
for c in curves:
    pts = r["curves"][c]
    assert len(pts) == 2, (c, pts)
    for p in pts:
        assert p["samples"] > 0 and p["seconds"] > 0, (c, p)
        assert math.isfinite(p["relmse"]) and 0 < p["relmse"] < 1, (c, p)
        assert 0 < p["ssim"] <= 1, (c, p)
    # Where twice the time gave clearly more samples, less error (noise-dominated here). Samples
    # per budget depend on the machine's load (other tests run beside this one) and Cycles'
    # defaults stop at their noise threshold, so fewer samples alone are no failure.
    if pts[1]["samples"] >= 1.5 * pts[0]["samples"]:
        assert pts[1]["relmse"] < pts[0]["relmse"], (c, pts)
cross = r["cross_engine_relmse"]["pt~cycles_unbiased"]
assert cross < 0.01 and not r["void"], cross
assert 1 < r["predicted_improvement"] < 1e3, r["predicted_improvement"]
assert 1 < r["gpt_cost_per_sample_over_pt"] < 10, r["gpt_cost_per_sample_over_pt"]
doc = open(os.path.join(out, "doc", "benchmarks.md")).read()
assert "## cornell_panel" in doc and "| cornell_panel |" in doc
rows = {line.split(" | ")[0]: line for line in doc.splitlines() if line.startswith("| ")}
speckles = next(v for k, v in rows.items() if "Filter Glossy 0, unbiased)" in k)
assert "Feature 0.50; isolated" in speckles and "at 2.00-2.00x the reference | met |" in speckles, speckles
speckles = next(v for k, v in rows.items() if "the demo's own Filter Glossy 1)" in k)
assert "Feature 0.25; isolated (the reference under 1.7x its median there) 8.0, 0.5, 0.25 | " \
    "**not met** |" in speckles, speckles
feature = next(v for k, v in rows.items() if k.startswith("| Feature at 1920x1080"))
assert "6.25 s = solves 2.00 s + filters 4.25 s | **not met** |" in feature, feature
l1 = next(v for k, v in rows.items() if k.startswith("| L1 at 1920x1080"))
assert "1.50 s, objective -0.0010% against L1D's | met |" in l1, l1
for f in ("cornell_panel_relmse.png", "cornell_panel_crops.png"):
    assert os.path.getsize(os.path.join(out, "doc", "benchmarks", f)) > 1000, f
print(f"ok: harness wrote every curve; references agree (relMSE {cross:.2e})")
PY
# --keep: Cycles' curves come from the run above, its renders are not made again, GDPT's are.
stamp() { stat -c %Y "$out/cache/cornell_panel_48x36/$1"; }
cp "$out/results/cornell_panel.json" "$out/first.json"
before=("$(stamp cycles_default_1s.exr)" "$(stamp cycles_unbiased_2s.exr)" "$(stamp pt_1s.exr)")
sleep 1
/usr/bin/python3 "$root/bench/report/run.py" --build "$build" --scenes cornell_panel \
  --budgets 1,2 --ref-seconds 3 --res 48x36 --results "$out/results" --cache "$out/cache" \
  --out-doc "$out/doc/benchmarks.md" --keep cycles_default,cycles_unbiased
[ "$(stamp cycles_default_1s.exr)" = "${before[0]}" ] && [ "$(stamp cycles_unbiased_2s.exr)" = "${before[1]}" ]
[ "$(stamp pt_1s.exr)" != "${before[2]}" ]
/usr/bin/python3 - "$out" <<'PY'
import json, os, sys
out = sys.argv[1]
first = json.load(open(os.path.join(out, "first.json")))
r = json.load(open(os.path.join(out, "results", "cornell_panel.json")))
for c in ("cycles_default", "cycles_unbiased"):
    assert r["curves"][c] == first["curves"][c], c
assert len(r["curves"]["pt"]) == 2 and r["curves"]["pt"] != first["curves"]["pt"]
assert r["meta"]["kept_from"]["commit"] == first["meta"]["commit"], r["meta"]
doc = open(os.path.join(out, "doc", "benchmarks.md")).read()
assert "Curves of cycles_default, cycles_unbiased are those of the run at commit" in doc
print("ok: --keep reused Cycles' curves and rendered GDPT's again")
PY
