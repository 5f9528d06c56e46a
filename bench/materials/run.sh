#!/usr/bin/env bash
# Renders a library of Blender material scripts with Gradient PT and Cycles (bench/materials/run.py)
# with the add-on staged from a build in a private folder; writes bench/results/materials.json and
# bench/results/materials.md. Not part of CI: the library is not in this repository.
#   bash bench/materials/run.sh <build-dir> <library dir> [--only NAME,...]
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
  --json "$root/bench/results/materials.json" --md "$root/bench/results/materials.md" "$@"
