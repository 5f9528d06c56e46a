#!/usr/bin/env bash
# Directional albedo of Blender nodes in Cycles 3.4 (GGX, CPU, 512 spp, 16x16 px) against GDPT's
# shaders (shaders_albedo): the two columns must agree within Cycles' noise (std of the mean =
# per-pixel std / 16). Usage: bench/shaders/cycles_albedo.sh BUILD_DIR
set -euo pipefail
build=${1:-build}
here=$(cd "$(dirname "$0")" && pwd)
tool="$build/bench/shaders/shaders_albedo"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
printf "%-44s %6s | %-26s %-8s | %s\n" case cos "cycles mean (r g b)" "std/16" "gdpt (r g b)"
while read -r case cos; do
  blender -b --factory-startup --python "$here/cycles_furnace.py" -- "$case" "$cos" \
    "$tmp/out.exr" 512 > "$tmp/log" 2>&1
  stats=$(oiiotool --stats "$tmp/out.exr")
  mean=$(echo "$stats" | awk '/Stats Avg/ {printf "%.4f %.4f %.4f", $3, $4, $5}')
  sd=$(echo "$stats" | awk '/Stats StdDev/ {printf "%.5f", $3 / 16}')
  printf "%-44s %6s | %-26s %-8s | %s\n" "$case" "$cos" "$mean" "$sd" "$("$tool" "$case" "$cos")"
done <<'CASES'
glossy_0.2 0.7
glossy_1.0 0.8
glossy_0.5 0.15
diffuse_1.0 0.5
diffuse_0.5 0.9
principled_0.8_0.8_0.8_0_0.5_0_0.5 0.5
principled_0.9_0.5_0.2_1_0.5_0_0.3 0.7
principled_0.8_0.1_0.1_0_1.0_0.7_0.2 0.3
principled_0.5_0.5_0.5_0.5_0.5_0_0.05 0.6
glass_0.3_1.5 0.6
glass_0.3_1.5 -0.9
glass_0.5_1.45 -0.95
glass_0.0_1.5 -0.8
ptrans_0.9_0.6_0.3_0.5_0.3_1.45_1.0 0.7
ptrans_0.9_0.6_0.3_0.0_0.4_1.45_0.6 -0.9
CASES
