#!/usr/bin/env bash
# `make fuzz`: builds the libFuzzer targets with clang in build-fuzz/ (GDPT_FUZZ=ON), seeds their
# corpora from real data written now (the project's EXR writer, oiiotool recompressions of it,
# meshes as the add-on hands them over), and runs each for FUZZ_SECONDS (default 60).
# A finding stops with its input in build-fuzz/artifacts/ and a non-zero exit.
# Usage: fuzz.sh [build-dir]
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${1:-build-fuzz}
SECONDS_EACH=${FUZZ_SECONDS:-60}
JOBS=${JOBS:-$(nproc)}

cmake -S . -B "$BUILD" -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=Release -DGDPT_FUZZ=ON \
  -DGDPT_BUILD_TESTS=OFF -DGDPT_BUILD_BENCH=OFF -DGDPT_BUILD_PYTHON=OFF >/dev/null
cmake --build "$BUILD" -j "$JOBS" --target fuzz_exr_io fuzz_mesh_ingest fuzz_seeds

seeds="$BUILD/seeds"
rm -rf "$seeds"
mkdir -p "$seeds/exr" "$seeds/mesh" "$BUILD/corpus/exr" "$BUILD/corpus/mesh" "$BUILD/artifacts"
"$BUILD/fuzz/fuzz_seeds" exr "$seeds/exr"
"$BUILD/fuzz/fuzz_seeds" mesh "$seeds/mesh"
# The same images as OpenEXR's other encodings: half floats, other compressions, tiles.
for f in "$seeds"/exr/blender_4x3.exr "$seeds"/exr/rgba_9x2.exr; do
  base=${f%.exr}
  oiiotool "$f" -d half -o "${base}_half.exr"
  for c in none rle zips piz pxr24 b44 dwaa; do
    oiiotool "$f" --compression "$c" -o "${base}_$c.exr"
  done
  oiiotool "$f" --tile 2 2 -o "${base}_tiled.exr"
done

status=0
for pair in exr:fuzz_exr_io mesh:fuzz_mesh_ingest; do
  target=${pair%%:*}
  fuzzer="$BUILD/fuzz/${pair#*:}"
  echo "fuzz: $fuzzer for ${SECONDS_EACH} s"
  # The corpus kept from earlier runs in $BUILD/corpus grows; the seeds are read, not written.
  "$fuzzer" -max_total_time="$SECONDS_EACH" -rss_limit_mb=2048 -max_len=65536 -print_final_stats=1 \
    -artifact_prefix="$BUILD/artifacts/${target}-" "$BUILD/corpus/$target" "$seeds/$target" \
    2>&1 | grep -vE '^#[0-9]+|^"|dictionary' || status=1
done
exit $status
