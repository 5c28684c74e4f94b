#!/usr/bin/env bash
# Adaptive simplification: triangles and meshing time with and without it
# (bench/mesh/run_simplify_bench.py), then the add-on's live update with and
# without it in headless Blender (bench/blender/bench_simplify.py), each
# beside meshoptimizer's collapses on the same mesh (bench_meshopt; in
# Blender through ctypes): what any collapse simplifier costs at least; the
# floor of a coarse-first mesher in the same Blender runs
# (bench/mesh/coarse_floor.py); and the triangles each leaves at a given
# error against the field (bench/mesh/run_meshopt_error.py); docs/meshing.md,
# Adaptive simplification.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake -S . -B build-release -G Ninja -DCMAKE_BUILD_TYPE=Release -DLIBBLEND_BENCH=ON >/dev/null
cmake --build build-release -j "$(nproc)" >/dev/null
/usr/bin/python3 bench/mesh/run_simplify_bench.py build-release/bench/bench_mesh . "${1:-3}"
echo
echo "meshoptimizer's meshopt_simplify against libblend (one thread, 0.1 cells, best of 5):"
for scene in scenes/bench-s1-three-spheres.json scenes/bench-s2-64-spheres.json; do
  for res in 64 128 256; do
    echo "$scene $(build-release/bench/bench_meshopt "$scene" "$res" 0.1 5)"
  done
done
echo
echo "triangles at a given error against the field (libblend against meshoptimizer):"
for res in 128 256; do
  PYTHONDONTWRITEBYTECODE=1 /usr/bin/python3 bench/mesh/run_meshopt_error.py \
    build-release/blender_addon/libblend_blender scenes/bench-s1-three-spheres.json "$res" 0.1 \
    0.1,0.05,0.03
done
PYTHONDONTWRITEBYTECODE=1 /usr/bin/python3 bench/mesh/run_meshopt_error.py \
  build-release/blender_addon/libblend_blender scenes/bench-s2-64-spheres.json 128 0.1 0.1,0.05
echo
PYTHONDONTWRITEBYTECODE=1 blender -b --factory-startup --python-exit-code 1 \
  --python bench/blender/bench_simplify.py -- build-release/blender_addon "$PWD" 2>&1 |
  grep -v '^Info: \|^Blender \|^Read \|^$'
