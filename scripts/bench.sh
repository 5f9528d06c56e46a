#!/usr/bin/env bash
# `make bench`: runs the equal-time report against Cycles first (bench/report/report.sh, which
# writes docs/benchmarks.md), then every benchmark executable (bench_*) of the build, one after
# the other, and every other bench/*/*.sh script (e.g. the Blender-vs-Cycles comparison), and
# last writes the report's page again (`run.py --doc-only`), so that its table of the Feature
# reconstruction's targets shows the demo's speckles and bench_reconstruct's 1920x1080 times of
# this run. Output goes to stdout and to out/bench/<name>.txt. QUICK=1 runs only the equal-time
# report, reduced (bench/report/report.sh: two scenes, short budgets; under ten minutes on 2 cores).
set -euo pipefail
build=${1:-build}
root=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$root/out/bench"
if [ "${QUICK:-0}" = 1 ]; then
  exec bash "$root/bench/report/report.sh" "$build"
fi
status=0
echo "=== report"
bash "$root/bench/report/report.sh" "$build" 2>&1 | tee "$root/out/bench/report.txt" || status=1
commit=$(git -C "$root" rev-parse --short HEAD)
while IFS= read -r exe; do
  name=$(basename "$exe")
  args=()
  # Its 1920x1080 figures feed the report's table of the reconstruction's targets.
  [ "$name" = bench_reconstruct ] && args=(--json "$root/bench/results/reconstruct.json" --commit "$commit")
  echo "=== $name"
  "$exe" "${args[@]}" 2>&1 | tee "$root/out/bench/$name.txt" || status=1
done < <(find "$build/bench" -type f -name 'bench_*' -perm -u+x | sort)
while IFS= read -r script; do
  name=$(basename "$script" .sh)
  echo "=== $name"
  bash "$script" "$build" 2>&1 | tee "$root/out/bench/$name.txt" || status=1
done < <(find "$root/bench" -mindepth 2 -name '*.sh' ! -path '*/report/*' ! -path '*/materials/*' | sort)
# The report's page again, with the targets table from the results just measured.
echo "=== report page"
/usr/bin/python3 "$root/bench/report/run.py" --build "$build" --doc-only || status=1
exit $status
