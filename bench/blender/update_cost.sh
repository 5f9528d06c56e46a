#!/usr/bin/env bash
# `make bench` (via scripts/bench.sh): the cost of progressive previews and of the fixed work
# around the core's render at full HD (bench/blender/update_cost.py).
#   bash bench/blender/update_cost.sh <build-dir>
set -euo pipefail
build=${1:-build}
root=$(cd "$(dirname "$0")/../.." && pwd)
case "$build" in /*) ;; *) build="$root/$build" ;; esac
scripts=$(mktemp -d)
trap 'rm -rf "$scripts"' EXIT
bash "$root/tests/blender/stage_addon.sh" "$root" "$build" "$scripts" >/dev/null
BLENDER_USER_SCRIPTS="$scripts" blender -b --factory-startup --addons gdpt --python-exit-code 1 \
  --python "$root/bench/blender/update_cost.py" 2>&1 | grep -E "^(BENCH|  )"
