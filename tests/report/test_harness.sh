#!/usr/bin/env bash
# The benchmark report's harness end to end on one tiny scene at 1 s budgets: every method
# renders with its own engine, the JSON holds finite errors for every curve, the engines'
# references agree, and the page and its figures are written.
#   test_harness.sh <build-dir> <out-dir>
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
build=$1 out=$2
rm -rf "$out"
mkdir -p "$out"
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
