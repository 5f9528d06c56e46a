#!/usr/bin/env bash
# Installs the Gradient PT add-on into the current user's Blender and enables it persistently, so
# that a plain `blender -b scene.blend -E GDPT -f 1` renders with it afterwards.
#   bash scripts/install-addon.sh <build-dir>
# Copies the add-on (scripts/assemble-addon.sh: blender_addon/gdpt and the built modules) into
# Blender's user add-on folder (as Blender itself reports it: ~/.config/blender/3.4/scripts/addons,
# or $BLENDER_USER_SCRIPTS/addons), then enables the add-on and saves the user preferences, and
# finally checks that a fresh Blender really lists the GDPT engine and imports the module.
set -euo pipefail
build=${1:-build}
root=$(cd "$(dirname "$0")/.." && pwd)
case "$build" in /*) ;; *) build="$root/$build" ;; esac
blender=${BLENDER:-blender}

addons=$("$blender" -b --factory-startup --python-expr \
  "import bpy; print('GDPT_ADDONS=' + bpy.utils.user_resource('SCRIPTS', path='addons', create=True))" \
  2>/dev/null | sed -n 's/^GDPT_ADDONS=//p')
if [ -z "$addons" ]; then
  echo "install-addon: could not ask Blender for its user add-on folder" >&2
  exit 1
fi

bash "$root/scripts/assemble-addon.sh" "$build" "$addons/gdpt"

# Enable and save the preferences (not --factory-startup: keep the user's other preferences).
"$blender" -b --python-expr "
import bpy, sys
bpy.ops.preferences.addon_enable(module='gdpt')
bpy.context.preferences.use_preferences_save = True
bpy.ops.wm.save_userpref()
print('GDPT_ENABLED')
" 2>&1 | grep -q GDPT_ENABLED || { echo "install-addon: enabling the add-on failed" >&2; exit 1; }

# A fresh Blender with the saved preferences must know the engine and load the module.
check=$("$blender" -b --python-expr "
import bpy, addon_utils
enabled = addon_utils.check('gdpt')[1]
engines = {e.bl_idname for e in bpy.types.RenderEngine.__subclasses__()}
from gdpt import _gdpt, native
print('GDPT_CHECK', enabled, 'GDPT' in engines, _gdpt.__file__, '(' + native.load()[1] + ' build)')
" 2>&1 | sed -n 's/^GDPT_CHECK //p')
case "$check" in
  "True True "*) echo "install-addon: enabled; Blender loads ${check#True True }" ;;
  *) echo "install-addon: check failed (got '$check')" >&2; exit 1 ;;
esac
