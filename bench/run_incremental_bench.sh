#!/usr/bin/env bash
# Incremental remeshing (lb_mesh_cache): one primitive moved by 1 % of the
# region, the mesh through the cache against a full remesh
# (bench/incremental/run_incremental_bench.py), then the add-on's live update
# of the same edit with and without the cache, against Blender's metaballs
# (bench/blender/bench_incremental.py); docs/meshing.md, Incremental
# remeshing, and docs/blender.md.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake -S . -B build-release -G Ninja -DCMAKE_BUILD_TYPE=Release -DLIBBLEND_BENCH=ON >/dev/null
cmake --build build-release -j "$(nproc)" >/dev/null
work=$(mktemp -d)
trap 'rm -rf -- "$work"' EXIT
/usr/bin/python3 bench/incremental/run_incremental_bench.py build-release/bench/bench_incremental \
  . "$work/c"
echo
PYTHONDONTWRITEBYTECODE=1 blender -b --factory-startup --python-exit-code 1 \
  --python bench/blender/bench_incremental.py -- build-release/blender_addon "$PWD" "$work/b" 2>&1 |
  grep -v '^Info: \|^Blender \|^Read \|^$'
