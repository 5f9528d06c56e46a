#!/usr/bin/env bash
# Test fixture: assembles the add-on from the source tree and the freshly built modules in a
# private Blender user-scripts folder, so the tests exercise this checkout (not whatever is
# installed in ~/.config/blender). Usage: stage_addon.sh <source-root> <build-dir> <user-scripts>
set -euo pipefail
bash "$1/scripts/assemble-addon.sh" "$2" "$3/addons/gdpt"
