#!/usr/bin/env bash
# OpenVDB level sets (blendtool vdb) against meshing the same scene at the
# same cell size: S2 at 256 and 512, one thread (bench/vdb/run_vdb_bench.py);
# docs/volumes.md, Speed.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake -S . -B build-release -G Ninja -DCMAKE_BUILD_TYPE=Release -DLIBBLEND_BENCH=ON >/dev/null
cmake --build build-release -j "$(nproc)" >/dev/null
work=$(mktemp -d)
trap 'rm -rf -- "$work"' EXIT
/usr/bin/python3 bench/vdb/run_vdb_bench.py build-release/tools/blendtool . "$work" "${1:-5}"
