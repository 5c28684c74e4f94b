#!/usr/bin/env bash
# The main job on the built-in default scene: install, build, run.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake -S . -B build-release -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build-release -j "$(nproc)"
./build-release/examples/blend_demo
