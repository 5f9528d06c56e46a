#!/usr/bin/env bash
# `make build`, second half: the add-on's `_gdpt` module compiled for a newer x86-64 level (GCC
# -march=<arch>, e.g. x86-64-v3: AVX2, FMA, BMI2), in <build>/<arch>, with its own PGO profile
# like the main build (scripts/pgo-train.sh; PGO=0 skips it). The training runs the new code, so
# the variant is only built on a CPU that runs it; elsewhere the add-on uses the baseline build.
# blender_addon/gdpt/native.py loads the variant when the CPU runs it.
#   bash scripts/build-variant.sh <build-dir> <arch>
set -euo pipefail
build=$1 arch=$2
root=$(cd "$(dirname "$0")/.." && pwd)
case "$build" in /*) ;; *) build="$root/$build" ;; esac
case "$arch" in
  x86-64-v2) needed=2 ;; x86-64-v3) needed=3 ;; x86-64-v4) needed=4 ;;
  *) echo "build-variant: unknown arch '$arch' (x86-64-v2, x86-64-v3 or x86-64-v4)" >&2; exit 1 ;;
esac
tree="$build/$arch"
shopt -s nullglob
cpu=("$build"/blender_addon/_gdpt_cpu.*so)
if [ ${#cpu[@]} -eq 0 ]; then
  echo "build-variant: no _gdpt_cpu module in $build/blender_addon (GDPT_BUILD_PYTHON=OFF?): no $arch build"
  exit 0
fi
# The CPU's level, from the module the add-on itself asks (built by the main build).
level=$(PYTHONPATH="$build/blender_addon" /usr/bin/python3 -c \
  'import _gdpt_cpu; print(_gdpt_cpu.x86_64_level())')
if [ "$level" -lt "$needed" ]; then
  echo "build-variant: this CPU is x86-64 level $level, it does not run $arch code: no $arch build" \
       "(the add-on uses the baseline build)"
  rm -rf "$tree/blender_addon"
  exit 0
fi
pgo=()
if [ "${PGO:-1}" = 1 ]; then
  if [ ! -f "$tree/pgo-profile/.trained" ]; then
    bash "$root/scripts/pgo-train.sh" "$tree" "$arch"
    touch "$tree/pgo-profile/.trained"
  fi
  pgo=(-DGDPT_PGO_USE="$tree/pgo-profile")
fi
# shellcheck disable=SC2086  # CMAKE_FLAGS: the Makefile's extra flags, word-split on purpose
cmake -S "$root" -B "$tree" -DCMAKE_BUILD_TYPE=Release -DGDPT_ARCH="$arch" -DGDPT_BUILD_TESTS=OFF \
  -DGDPT_BUILD_BENCH=OFF "${pgo[@]}" ${CMAKE_FLAGS:-} > /dev/null
cmake --build "$tree" -j "${JOBS:-$(nproc)}" --target _gdpt
