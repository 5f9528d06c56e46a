#!/usr/bin/env bash
# Runs test_viewport.py in Blender with a window on Xvfb (Mesa's software OpenGL) and checks that
# it passed and that Blender quit with 0. Usage: test_viewport.sh <blender> <test dir> <out dir>
set -uo pipefail
blender=$1 dir=$2 out=$3
mkdir -p "$out"
log="$out/blender.log"
"$blender" -b --factory-startup --addons gdpt --python-exit-code 1 \
  --python "$dir/test_viewport.py" -- --make "$out/scene.blend" > "$out/make.log" 2>&1 ||
  { cat "$out/make.log"; echo "test_viewport.sh: the scene was not made"; exit 1; }
xvfb-run -a -s "-screen 0 1280x800x24" "$blender" --factory-startup --addons gdpt \
  "$out/scene.blend" --python-exit-code 1 --python "$dir/test_viewport.py" -- --out "$out" 2>&1 |
  tee "$log"
rc=${PIPESTATUS[0]}
if [[ $rc -ne 0 ]]; then
  echo "test_viewport.sh: Blender exited with $rc"
  exit 1
fi
grep -q "^viewport test passed" "$log" || { echo "test_viewport.sh: no pass line"; exit 1; }
