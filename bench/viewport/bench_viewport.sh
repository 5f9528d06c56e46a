#!/usr/bin/env bash
# The viewport benchmark (not in CI): builds the demo scene, then runs bench_viewport.py in
# Blender with a window on Xvfb, the add-on staged from a build directory.
#   bash bench/viewport/bench_viewport.sh [build-dir [baseline-root baseline-build-dir]]
# With a baseline (a source tree of another version and its build), that version's Gradient PT
# runs first ("baseline" lines), then this one's and Cycles', so the ratios come from one run.
# Knobs (environment): GDPT_BENCH_REF_SAMPLES (256, the references), GDPT_BENCH_STILL_SAMPLES (4),
# GDPT_BENCH_REUSE_REFS (1: references of an earlier run with the same sample count are kept).
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-build}
case "$build" in /*) ;; *) build="$root/$build" ;; esac
out="$root/out/bench/viewport"
mkdir -p "$out"
scripts=$(mktemp -d)
trap 'rm -rf "$scripts"' EXIT
bash "$root/tests/blender/stage_addon.sh" "$root" "$build" "$scripts" >/dev/null
export BLENDER_USER_SCRIPTS="$scripts"
blender -b --factory-startup --addons gdpt --python-exit-code 1 \
  --python "$root/blender_addon/demo/make_demo_scene.py" -- "$out/demo.blend" >/dev/null
# One Blender with a window: bench_viewport.py with the add-on staged in $1, arguments after.
run() {
  BLENDER_USER_SCRIPTS="$1" xvfb-run -a -s "-screen 0 1280x800x24" blender --factory-startup \
    --addons gdpt "$out/demo.blend" --python-exit-code 1 \
    --python "$root/bench/viewport/bench_viewport.py" -- --out "$out" "${@:2}" 2>&1
}
: >"$out/blender.log"
if [ $# -ge 3 ]; then
  baseline=$(mktemp -d)
  trap 'rm -rf "$scripts" "$baseline"' EXIT
  bash "$root/tests/blender/stage_addon.sh" "$2" "$3" "$baseline" >/dev/null
  run "$baseline" --engines GDPT --label baseline | tee -a "$out/blender.log" | grep -E "^BENCH"
  export GDPT_BENCH_REUSE_REFS=1  # the references it rendered
fi
run "$scripts" | tee -a "$out/blender.log" | grep -E "^BENCH"
