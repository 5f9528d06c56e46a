#!/usr/bin/env bash
# A/B render time of two staged add-ons in Blender on a 2-core machine whose speed drifts: two
# Blender processes at once, each rendering with one thread pinned to its own core, then with
# the cores swapped (as scripts/ab-cores.sh does for the C++ benchmark). Prints one line per
# process: add-on, core, render times in seconds (bench/blender/ab_render.py).
#   bash scripts/ab-blender.sh <user-scripts A> <user-scripts B> [cornell|textured] [rounds]
# Stage each build's add-on first: bash tests/blender/stage_addon.sh . <build> <user-scripts>.
set -euo pipefail
a=$1 b=$2 scene=${3:-cornell} rounds=${4:-2}
root=$(cd "$(dirname "$0")/.." && pwd)
run() {  # run <label> <user-scripts> <core>
  echo "$1 core $3 $(GDPT_AB_SCENE=$scene BLENDER_USER_SCRIPTS=$2 taskset -c "$3" blender -b \
    --factory-startup --addons gdpt --python "$root/bench/blender/ab_render.py" 2>&1 | grep '^AB')"
}
for _ in $(seq "$rounds"); do
  for cores in "0 1" "1 0"; do
    read -r ca cb <<< "$cores"
    run A "$a" "$ca" &
    run B "$b" "$cb"
    wait
  done
done | sort
