#!/usr/bin/env bash
# `make bench` (via scripts/bench.sh): the cost of progressive previews and of the fixed work
# around the core's render at full HD (bench/blender/update_cost.py).
#   bash bench/blender/update_cost.sh <build-dir>
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
bash "$root/scripts/blender-bench.sh" "${1:-build}" "$root/bench/blender/update_cost.py"
