#!/usr/bin/env bash
# The Blender add-on benchmark (docs/blender.md): builds, then runs
# bench/blender/bench_live.py in headless Blender and prints the table.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake -S . -B build-release -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build-release -j "$(nproc)" >/dev/null
PYTHONDONTWRITEBYTECODE=1 blender -b --factory-startup --python-exit-code 1 \
  --python bench/blender/bench_live.py -- build-release/blender_addon "$PWD" 2>&1 |
  grep -v '^Info: \|^Blender \|^Read \|^$'
