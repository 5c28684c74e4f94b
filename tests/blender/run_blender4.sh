#!/usr/bin/env bash
# The add-on on Blender 4.x, as a 4.2+ extension, run inside the Debian 13
# root (scripts/debian-root.sh trixie-blender4 run ... -- bash run_blender4.sh ...):
#   run_blender4.sh ADDON_DIR BLENDTOOL SOURCE_DIR WORK_DIR
# Blender's own tools validate and build the extension from the add-on
# folder of the build tree (ADDON_DIR: bl_info and blender_manifest.toml side
# by side) and install the zip into a scratch user folder
# (BLENDER_USER_RESOURCES); then the same headless tests as on 3.4 run
# against the installed extension (bl_ext.user_default.libblend).
set -euo pipefail
addon=$1 blendtool=$2 src=$3 work=$4
rm -rf "$work"
mkdir -p "$work/dist"
export BLENDER_USER_RESOURCES="$work/user" PYTHONDONTWRITEBYTECODE=1
bl() { blender -b --factory-startup "$@"; }
echo "== $(bl --version 2>/dev/null | head -1)"
echo "== extension validate"
bl --command extension validate "$addon"
echo "== extension build"
bl --command extension build --source-dir "$addon" --output-dir "$work/dist"
zip=$(ls "$work"/dist/*.zip)
echo "== extension install-file $zip"
bl --command extension install-file -r user_default -e "$zip"
test -f "$work/user/extensions/user_default/libblend/lib/libblend.so" ||
  { echo "run_blender4: the installed extension has no lib/libblend.so" >&2; exit 1; }
for t in test_addon test_animation; do
  echo "== $t (Blender 4.x, extension)"
  bl --python-exit-code 1 --python "$src/tests/blender/$t.py" -- \
    ext:bl_ext.user_default.libblend "$blendtool" "$src" "$work/$t"
done
