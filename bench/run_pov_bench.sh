#!/usr/bin/env bash
# The POV-Ray render benchmark (povray_include/README.md, "Speed"): builds
# blendtool, exports hsu2006 Fig. 7 and S1, and renders each at 640 x 480 as
# libblend's blend, as a plain min() of the same primitives and as a
# hand-written smooth-min (S1 also as POV-Ray's native blob), in one run.
# usage: bash bench/run_pov_bench.sh [SCENE.json...]   (default: both scenes)
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake -S . -B build-release -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build-release -j "$(nproc)" --target blendtool >/dev/null
/usr/bin/python3 bench/pov/run_pov_bench.py build-release/tools/blendtool . build-release/pov-bench "$@"
