#!/usr/bin/env bash
# Profile-guided optimisation, training half (`make build` runs it once per build directory):
# builds an instrumented copy of the core and the two kernel benchmarks in <build>/pgo-train,
# renders the benchmark scenes with them (PT on the Cornell box, the Blender Cornell box and the
# textured box; G-PT on the diffuse, glossy and depth-of-field boxes), and leaves the profile in
# <build>/pgo-profile, which the real build reads (CMake option GDPT_PGO_USE). Delete
# <build>/pgo-profile to train again (e.g. after large changes to the kernels). With an arch
# (scripts/build-variant.sh), the training tree is compiled with -march=<arch>.
#   bash scripts/pgo-train.sh <build-dir> [arch]
set -euo pipefail
build=${1:-build}
arch=${2:-}
root=$(cd "$(dirname "$0")/.." && pwd)
case "$build" in /*) ;; *) build="$root/$build" ;; esac
train="$build/pgo-train"
profile="$build/pgo-profile"
rm -rf "$profile" "$profile.tmp"
cmake -S "$root" -B "$train" -DCMAKE_BUILD_TYPE=Release -DGDPT_BUILD_TESTS=OFF \
  -DGDPT_BUILD_PYTHON=OFF -DGDPT_ARCH="$arch" -DGDPT_PGO_GENERATE="$profile.tmp" > /dev/null
cmake --build "$train" -j "$(nproc)" --target bench_integrator bench_gradient
# Fixed sample counts with one thread: the counts (hence the profile) do not depend on timing.
GDPT_BENCH_SPP=8 "$train/bench/integrator/bench_integrator" 0 cornell,blender,textured
for case in cornell glossy-0.09 glossy-4e-4 cornell-dof; do
  GDPT_BENCH_CASE=$case GDPT_BENCH_MODE=gpt "$train/bench/gradient/bench_gradient" 64 4 1 1
done
mv "$profile.tmp" "$profile"
echo "pgo-train: profile in $profile"
