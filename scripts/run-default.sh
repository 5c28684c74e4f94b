#!/usr/bin/env bash
# The main job on the built-in default scene (scenes/default.json): install
# what is missing, build, then validate every shipped scene, describe the
# default one, evaluate its field and gradient along a line through it, and
# mesh it (build-release/default.ply).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake -S . -B build-release -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build-release -j "$(nproc)"
blendtool=./build-release/tools/blendtool
"$blendtool" validate scenes/*.json
"$blendtool" info scenes/default.json
echo "# value gx gy gz along the y axis, through the cube and the blended super-ellipsoid"
for y in -1.2 -0.9 0 0.9 1.0 1.1 1.35 1.9 2.1; do echo "0 $y 0"; done |
  "$blendtool" eval scenes/default.json
"$blendtool" mesh scenes/default.json -o build-release/default.ply --resolution 256
echo "# the Blender add-on, ready to install (Preferences > Add-ons > Install):"
ls build-release/blender_addon/libblend_blender-*.zip
