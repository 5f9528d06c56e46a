#!/usr/bin/env bash
# Renders a library of Blender materials (scripts, .blend files) with Gradient PT and Cycles
# (bench/materials/run.py) with the add-on staged from a build in a private folder; writes
# bench/results/$RESULTS.json and .md (RESULTS defaults to materials). Not part of CI: the library
# is not in this repository.
#   [RESULTS=name] bash bench/materials/run.sh <build-dir> <library dir> [--only NAME,...]
#     [--source 'owner/repo@commit (licence)']
set -euo pipefail
build=$1 lib=$2
shift 2
root=$(cd "$(dirname "$0")/../.." && pwd)
if [ ! -d "$lib" ]; then
  echo "materials: library folder '$lib' not found (make materials LIB=/path/to/material/scripts)" >&2
  exit 2
fi
stage=$(mktemp -d)
trap 'rm -rf "$stage"' EXIT
bash "$root/scripts/assemble-addon.sh" "$build" "$stage/addons/gdpt"
BLENDER_USER_SCRIPTS="$stage" blender -b --factory-startup --addons gdpt --python-exit-code 1 \
  --python "$root/bench/materials/run.py" -- --lib "$(cd "$lib" && pwd)" --out "$stage/renders" \
  --json "$root/bench/results/${RESULTS:-materials}.json" \
  --md "$root/bench/results/${RESULTS:-materials}.md" "$@"
