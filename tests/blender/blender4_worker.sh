#!/usr/bin/env bash
# Blender 4.x of the Debian 13 root (scripts/debian-root.sh trixie-blender4)
# standing in for `blender` on a farm node: blendtool batch --blender THIS.
# The root sees the temporary folder (the tasks' scenes and images) and the
# add-on folder ($LIBBLEND_BLENDER_ADDON, which the test sets) at their own
# paths; the worker's pipes (fd 3 and 4) pass through unshare and chroot,
# which exec in place, so Blender is still blendtool's child.
set -euo pipefail
src=$(cd "$(dirname "$0")/../.." && pwd)
: "${LIBBLEND_BLENDER_ADDON:?set it to the folder holding libblend_blender/}"
exec bash "$src/scripts/debian-root.sh" trixie-blender4 run "${TMPDIR:-/tmp}" \
  "$LIBBLEND_BLENDER_ADDON" -- blender "$@"
