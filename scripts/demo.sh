#!/usr/bin/env bash
# `make demo`: generates the demo scene in Blender (blender_addon/demo/make_demo_scene.py) into
# out/demo/demo.blend, renders it headless with Gradient PT exactly as a farm would
# (`blender -b out/demo/demo.blend -E GDPT -f 1`) and prints where the image is.
#   bash scripts/demo.sh <build-dir>   (the add-on must be installed: make demo does that)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
blender=${BLENDER:-blender}
out="$root/out/demo"
mkdir -p "$out"
rm -f "$out"/demo_0001.png

"$blender" -b --python-exit-code 1 --python "$root/blender_addon/demo/make_demo_scene.py" -- \
  "$out/demo.blend" >"$out/make_scene.log" 2>&1 \
  || { cat "$out/make_scene.log"; echo "demo: could not build the scene (is the add-on installed?)" >&2; exit 1; }

"$blender" -b "$out/demo.blend" -E GDPT -f 1 2>&1 | tee "$out/render.log" | grep -E "^GDPT:|Saved:" || true
if ! grep -q "^GDPT: view layer .* finished" "$out/render.log"; then
  echo "demo: Gradient PT did not render (see $out/render.log)" >&2
  exit 1
fi
if [ ! -s "$out/demo_0001.png" ]; then
  echo "demo: no image written (see $out/render.log)" >&2
  exit 1
fi
echo "demo: rendered image: $out/demo_0001.png"
