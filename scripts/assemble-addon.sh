#!/usr/bin/env bash
# Assembles the Gradient PT add-on folder from this checkout and a build: blender_addon/gdpt, the
# `_gdpt` and `_gdpt_cpu` modules, and the x86-64-v3 build of `_gdpt` when scripts/build-variant.sh
# made one (into x86-64-v3/; blender_addon/gdpt/native.py picks the build at import). An x86-64-v3
# module older than the baseline one was built from older sources and is left out, with a note.
# Used by scripts/install-addon.sh and by the tests' and benchmarks' private staging.
#   bash scripts/assemble-addon.sh <build-dir> <add-on folder, e.g. .../scripts/addons/gdpt>
set -euo pipefail
build=$1 dest=$2
root=$(cd "$(dirname "$0")/.." && pwd)
shopt -s nullglob
modules=("$build"/blender_addon/_gdpt.*so)
cpu=("$build"/blender_addon/_gdpt_cpu.*so)
if [ ${#modules[@]} -eq 0 ] || [ ${#cpu[@]} -eq 0 ]; then
  echo "assemble-addon: no _gdpt / _gdpt_cpu module in $build/blender_addon (build first: make build)" >&2
  exit 1
fi
rm -rf "$dest"
mkdir -p "$dest"
cp -r "$root"/blender_addon/gdpt/. "$dest"/
find "$dest" -name '__pycache__' -prune -exec rm -rf {} +
cp "${modules[0]}" "${cpu[0]}" "$dest"/
copied="$(basename "${modules[0]}")"
variant=("$build"/x86-64-v3/blender_addon/_gdpt.*so)
if [ ${#variant[@]} -gt 0 ]; then
  if [ "${variant[0]}" -nt "${modules[0]}" ]; then
    mkdir -p "$dest/x86-64-v3"
    cp "${variant[0]}" "$dest/x86-64-v3/"
    copied+=" and its x86-64-v3 build"
  else
    echo "assemble-addon: ${variant[0]} is older than the baseline module, left out (make build" \
         "rebuilds it)" >&2
  fi
fi
echo "assemble-addon: $copied in $dest"
