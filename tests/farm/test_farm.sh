#!/usr/bin/env bash
# The render farm on localhost (ctest farm.localhost): a private single-node Slurm cluster
# (local_slurm.sh), `gdpt-farm submit` of a small scene split into 3 sample ranges (an array job
# and a dependent gdpt-merge job), `gdpt-farm status --wait`, and the merged EXR compared with a
# single-machine render of all its samples (compare_exr.py: every channel within float
# rounding). Also the refusals: no sbatch on PATH, a .blend that does not render with GDPT, and a
# task whose Blender did not render with Gradient PT (the merge job is then cancelled).
# The daemons are stopped on every exit path.
#   test_farm.sh <blender> <source dir> <build dir> <out dir>
set -euo pipefail
blender=$1 src=$2 build=$3 out=$4
here=$src/tests/farm
farm=$src/scripts/gdpt-farm
merge=$build/reconstruct/gdpt-merge
rm -rf "$out"
mkdir -p "$out"
source "$here/local_slurm.sh"
trap local_slurm_stop EXIT

fail() { echo "FAIL: $*"; exit 1; }

# --- the scenes ---
"$blender" -b --factory-startup --addons gdpt --python-exit-code 1 \
  --python "$here/make_farm_scene.py" -- "$out" >"$out/make.log" 2>&1 \
  || { cat "$out/make.log"; fail "could not make the scenes"; }
scene=$out/scene_GDPT.blend

# --- refusals, before any Slurm exists ---
set +e
mkdir -p "$out/empty_path"  # /bin is /usr/bin on Debian: a PATH without Slurm is an empty one
msg=$(PATH=$out/empty_path /usr/bin/python3 "$farm" submit "$scene" --frame 1 --jobs 2 \
  --out "$out/x" 2>&1)
status=$?
set -e
[ $status = 2 ] && grep -q "sbatch not found" <<<"$msg" || fail "no sbatch: exit $status: $msg"
echo "ok: without sbatch: $msg"

local_slurm_start "$out/slurm" 2

set +e
msg=$("$farm" submit "$out/scene_BLENDER_EEVEE.blend" --frame 1 --jobs 2 --out "$out/x" \
  --blender "$blender" --merge "$merge" 2>&1)
status=$?
set -e
[ $status = 2 ] && grep -q "renders with BLENDER_EEVEE, not Gradient PT" <<<"$msg" \
  || fail "EEVEE scene: exit $status: $msg"
echo "ok: an EEVEE .blend: $msg"

# --- the farm: 12 samples in 3 jobs of one thread each ---
start=$(date +%s)
"$farm" submit "$scene" --frame 1 --jobs 3 --out "$out/farm" --threads 1 \
  --blender "$blender" --merge "$merge" || fail "gdpt-farm submit"
"$farm" status "$out/farm" --wait --timeout 240 --interval 1 \
  || { tail -n 30 "$out"/farm/logs/*; fail "gdpt-farm status --wait"; }
echo "ok: the farm rendered and merged in $(( $(date +%s) - start )) s"
for i in 0 1 2; do
  grep -q "^GDPT: view layer 'ViewLayer' finished: 4/4 samples" "$out/farm/logs/task_$i.out" \
    || { cat "$out/farm/logs/task_$i.out"; fail "task $i did not render 4 samples with GDPT"; }
done
merged=$out/farm/scene_GDPT_0001.exr
report=$("$farm" status "$out/farm")
for line in "task 0 (samples 0..3): COMPLETED" "task 2 (samples 8..11): COMPLETED" \
            "merge (job [0-9]*): COMPLETED"; do
  grep -q "$line" <<<"$report" || fail "gdpt-farm status lacks '$line':"$'\n'"$report"
done

# --- a task whose Blender exits 0 without rendering (as one without the add-on falls back to
# EEVEE) fails, and the merge never runs ---
cat >"$out/fake_blender" <<FAKE
#!/bin/bash
case "\$*" in *GDPT-FARM-PROBE*) exec "$blender" "\$@" ;; esac
echo "Fra:1 Mem:1M | Rendering with another engine"
FAKE
chmod +x "$out/fake_blender"
"$farm" submit "$scene" --frame 1 --jobs 2 --out "$out/fallback" --threads 1 \
  --blender "$out/fake_blender" --merge "$merge" >/dev/null || fail "submit with a fake Blender"
set +e
report=$("$farm" status "$out/fallback" --wait --timeout 120 --interval 1 2>&1)
status=$?
set -e
[ $status = 1 ] && grep -q "task 0 (samples 0..5): FAILED" <<<"$report" \
  && grep -q "merge (job [0-9]*): CANCELLED" <<<"$report" \
  && grep -q "the job ended without" <<<"$report" \
  || fail "a task that did not render with GDPT: exit $status:"$'\n'"$report"
grep -q "Gradient PT did not render" "$out"/fallback/logs/task_0.out \
  || fail "the failed task does not say why"
echo "ok: a task without Gradient PT fails and cancels the merge"

# --- the oracle: one machine, all 12 samples ---
"$blender" -b "$scene" --addons gdpt -E GDPT --python-expr "import bpy
s = bpy.context.scene
s.render.image_settings.file_format = 'OPEN_EXR_MULTILAYER'
s.render.image_settings.color_depth = '32'
s.render.filepath = '$out/single_'" -f 1 >"$out/single.log" 2>&1 \
  || { cat "$out/single.log"; fail "single render"; }
grep -q "^GDPT: view layer 'ViewLayer' finished: 12/12 samples" "$out/single.log" \
  || { cat "$out/single.log"; fail "the single render did not take 12 samples with GDPT"; }
/usr/bin/python3 "$here/compare_exr.py" "$merged" "$out/single_0001.exr" \
  "$out"/farm/parts/part00*_0001.exr
