#!/usr/bin/env bash
# `make bench` (via scripts/bench.sh): Gradient PT (PT mode) against Cycles in one Blender run:
# samples/s ratio and relMSE at equal samples against each engine's own converged image, on a
# Cornell box and a textured scene; export time of a 1M-triangle mesh; add-on overhead.
#   bash bench/blender/compare_cycles.sh <build-dir>
# Knobs (environment): GDPT_BENCH_RES (default 96x72), GDPT_BENCH_SAMPLES (32),
# GDPT_BENCH_REF_SAMPLES (512), GDPT_BENCH_REPEATS (3, reference renders per engine, median
# time), GDPT_BENCH_BOUNCES (4), GDPT_BENCH_MIN_LIGHT_BOUNCES (0,2,defaults: one comparison per
# entry, a number being set in both engines, "defaults" each engine's own),
# GDPT_BENCH_CYCLES_PATTERN (PROGRESSIVE_MULTI_JITTER, Cycles' default, or SOBOL).
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
out="$root/out/bench/blender"
mkdir -p "$out"
bash "$root/scripts/blender-bench.sh" "${1:-build}" "$root/bench/blender/compare_cycles.py" \
  --out "$out"
