#!/usr/bin/env bash
# The equal-time report against Cycles (bench/report/run.py): writes bench/results/<scene>.json,
# docs/benchmarks.md and its figures. QUICK=1: two scenes, short budgets, small frames.
# KEEP=cycles_default,cycles_unbiased: Cycles' curves from the previous results (run.py --keep).
#   report.sh <build-dir>
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
args=(--build "$1")
if [ "${QUICK:-0}" = 1 ]; then args+=(--quick); fi
if [ -n "${KEEP:-}" ]; then args+=(--keep "$KEEP"); fi
exec /usr/bin/python3 "$root/bench/report/run.py" "${args[@]}"
