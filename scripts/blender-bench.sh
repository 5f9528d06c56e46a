#!/usr/bin/env bash
# Runs a benchmark script in a headless Blender with the add-on staged from a build directory
# (into a private BLENDER_USER_SCRIPTS, nothing installed), printing the script's result lines
# (those starting with "BENCH" or two spaces). Used by bench/blender/*.sh.
#   bash scripts/blender-bench.sh <build-dir> <script.py> [script arguments after --]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-build}
script=$2
shift 2
case "$build" in /*) ;; *) build="$root/$build" ;; esac
scripts=$(mktemp -d)
trap 'rm -rf "$scripts"' EXIT
bash "$root/tests/blender/stage_addon.sh" "$root" "$build" "$scripts" >/dev/null
BLENDER_USER_SCRIPTS="$scripts" blender -b --factory-startup --addons gdpt --python-exit-code 1 \
  --python "$script" -- "$@" 2>&1 | grep -E "^(BENCH|  )"
