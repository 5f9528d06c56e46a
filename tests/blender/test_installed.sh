#!/usr/bin/env bash
# The user installation made by scripts/install-addon.sh works with plain command lines, as a
# render farm uses them: no --addons, no scripts. A .blend saved with engine GDPT is rendered
# with `-E GDPT -f 1` and with `-a` (two frames). Blender silently falls back to EEVEE (exit 0)
# when the add-on is missing, so the test requires the engine's own console lines and outputs.
#   test_installed.sh <blender> <tests/blender dir> <out dir>
set -euo pipefail
blender=$1 here=$2 out=$3
rm -rf "$out"
mkdir -p "$out"

"$blender" -b --python-exit-code 1 --python "$here/make_installed_scene.py" -- "$out/scene.blend" \
  >"$out/make.log" 2>&1 || { cat "$out/make.log"; echo "FAIL: could not create the scene"; exit 1; }

"$blender" -b "$out/scene.blend" -E GDPT -f 1 >"$out/f1.log" 2>&1 || { cat "$out/f1.log"; exit 1; }
grep -q "^GDPT: view layer 'ViewLayer' finished: 16/16 samples" "$out/f1.log" \
  || { cat "$out/f1.log"; echo "FAIL: -f 1 did not render with Gradient PT"; exit 1; }
grep -q "Sample 16/16" "$out/f1.log" || { echo "FAIL: no 'Sample k/N' progress line"; exit 1; }
[ -s "$out/frame_0001.exr" ] || { echo "FAIL: -f 1 wrote no image"; exit 1; }
echo "ok: blender -b scene.blend -E GDPT -f 1"

"$blender" -b "$out/scene.blend" -E GDPT -a >"$out/anim.log" 2>&1 || { cat "$out/anim.log"; exit 1; }
count=$(grep -c "^GDPT: view layer 'ViewLayer' finished" "$out/anim.log" || true)
[ "$count" = 2 ] || { cat "$out/anim.log"; echo "FAIL: -a rendered $count frames, expected 2"; exit 1; }
[ -s "$out/frame_0002.exr" ] || { echo "FAIL: -a wrote no second frame"; exit 1; }
echo "ok: blender -b scene.blend -E GDPT -a (2 frames)"
