#!/usr/bin/env bash
# Image texture conventions (v = 0 at the bottom, pixel centres, Closest/Linear x
# Repeat/Extend/Clip, Mapping node) in Cycles 3.4 against Texture::lookup. Closest must match
# exactly; Linear within ~0.005 (Cycles' sub-pixel jitter on gradients).
# Usage: bench/shaders/cycles_texture.sh BUILD_DIR
set -euo pipefail
build=${1:-build}
here=$(cd "$(dirname "$0")" && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for interp in Closest Linear; do
  for ext in REPEAT EXTEND CLIP; do
    blender -b --factory-startup --python "$here/cycles_texture.py" -- "$interp" "$ext" \
      "$tmp/out.exr" > "$tmp/log" 2>&1
    "$build/bench/shaders/shaders_texture_check" "$interp" "$ext" "$tmp/out.exr"
  done
done
