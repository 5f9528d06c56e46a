#!/usr/bin/env bash
# Test fixture: assembles the add-on from the source tree and the freshly built module in a
# private Blender user-scripts folder, so the tests exercise this checkout (not whatever is
# installed in ~/.config/blender). Usage: stage_addon.sh <source-root> <module.so> <user-scripts>
set -euo pipefail
src=$1 module=$2 dest=$3/addons/gdpt
rm -rf "$dest"
mkdir -p "$dest"
cp -r "$src"/blender_addon/gdpt/. "$dest"/
find "$dest" -name '__pycache__' -prune -exec rm -rf {} +
cp "$module" "$dest"/
echo "staged the add-on in $dest"
