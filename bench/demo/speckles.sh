#!/usr/bin/env bash
# `make bench` (via scripts/bench.sh): bright speckles and relMSE of the demo at its default
# samples, L1 against Feature (bench/demo/speckles.py), with Filter Glossy 0 (unbiased) and with
# the demo's own 1.0 (writes bench/results/demo_speckles.json and
# demo_speckles_filter_glossy_1.json).
#   bash bench/demo/speckles.sh <build-dir>
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
/usr/bin/python3 "$root/bench/demo/speckles.py" --build "${1:-build}"
/usr/bin/python3 "$root/bench/demo/speckles.py" --build "${1:-build}" --filter-glossy 1
