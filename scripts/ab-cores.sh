#!/usr/bin/env bash
# A/B timing of two builds of a benchmark on a 2-core machine whose speed drifts from minute to
# minute: both run at the same time, one pinned to each core, then with the cores swapped, so
# drift and a slower core affect both alike. Prints one line per run: build, core, seconds.
#   bash scripts/ab-cores.sh <bench_integrator A> <bench_integrator B> [case] [spp] [rounds]
# e.g. bash scripts/ab-cores.sh build-a/bench/integrator/bench_integrator \
#        build-b/bench/integrator/bench_integrator blender 24 3
# (GDPT_BENCH_SPP renders exactly that many samples per pixel with one thread.)
set -euo pipefail
a=$1 b=$2 case=${3:-blender} spp=${4:-24} rounds=${5:-3}
for _ in $(seq "$rounds"); do
  for cores in "0 1" "1 0"; do
    read -r ca cb <<< "$cores"
    ( /usr/bin/time -f "A core $ca %e s" taskset -c "$ca" env GDPT_BENCH_SPP="$spp" "$a" 0 "$case" \
        > /dev/null ) 2>&1 &
    ( /usr/bin/time -f "B core $cb %e s" taskset -c "$cb" env GDPT_BENCH_SPP="$spp" "$b" 0 "$case" \
        > /dev/null ) 2>&1
    wait
  done
done | sort
