#!/usr/bin/env bash
# `make bench` (via scripts/bench.sh, after the report that fills bench/results/cache): Feature
# against L1 at the report's 5 s sample counts over five seeds (bench/reconstruct/
# feature_low_samples.py; writes bench/results/feature_low_samples.json).
#   bash bench/reconstruct/feature_low_samples.sh <build-dir>
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
/usr/bin/python3 "$root/bench/reconstruct/feature_low_samples.py" --build "${1:-build}"
