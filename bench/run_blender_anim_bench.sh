#!/usr/bin/env bash
# The Blender animation benchmark (docs/blender.md, Animation): builds, then
# runs bench/blender/bench_anim.py in headless Blender 3.4: a 24-frame
# animation render of the S2 lattice with animated m at render resolution
# 128 (Cycles, 1 sample, 320x240), the same render of a static mesh, Blender's
# metaballs on the same balls, and a 24-frame bake, all in one run.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake -S . -B build-release -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build-release -j "$(nproc)" >/dev/null
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
PYTHONDONTWRITEBYTECODE=1 blender -b --factory-startup --python-exit-code 1 \
  --python bench/blender/bench_anim.py -- build-release/blender_addon "$PWD" "$work" 2>&1 |
  grep '^BENCH '
