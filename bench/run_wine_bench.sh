#!/usr/bin/env bash
# The Windows DLL under Wine against the Linux .so on this machine
# (docs/portability.md, "Speed under Wine"): bench_platform built for both
# systems (the same source, public API only; Linux links libblend.so, the
# Windows program libblend.dll), run in alternation ROUNDS times (default 3)
# so that both see the same load; each row keeps its shortest time over the
# rounds and prints the ratio Wine / Linux (1.00: the same speed; above 1:
# slower under Wine). The checksums of the two must agree: both computed the
# same numbers.
#   bash bench/run_wine_bench.sh [ROUNDS] [--quick]
set -euo pipefail
cd "$(dirname "$0")/.."
ROUNDS=${1:-3}
QUICK=${2:-}
bash scripts/install-deps.sh >/dev/null
cmake -S . -B build-release -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build-release --target bench_platform >/dev/null
cmake -S . -B build-wine-bench -G Ninja -DCMAKE_BUILD_TYPE=Release -DLIBBLEND_TESTS=OFF \
  -DLIBBLEND_BENCH=ON -DCMAKE_TOOLCHAIN_FILE=cmake/mingw-w64-x86_64.cmake >/dev/null
cmake --build build-wine-bench --target bench_platform >/dev/null
tmp=$(mktemp -d /tmp/libblend-wine-bench.XXXXXX)
trap 'rm -rf "$tmp"' EXIT
trap 'exit 130' INT TERM
cp build-wine-bench/bench/bench_platform.exe build-wine-bench/libblend/libblend.dll "$tmp/"
scene=$PWD/scenes/default.json
bash scripts/wine-run.sh "$tmp/bench_platform.exe" "$scene" --quick >/dev/null # the prefix, warm
for ((r = 1; r <= ROUNDS; r++)); do
  build-release/bench/bench_platform "$scene" $QUICK >"$tmp/linux.$r"
  bash scripts/wine-run.sh "$tmp/bench_platform.exe" "$scene" $QUICK | tr -d '\r' >"$tmp/wine.$r"
done
/usr/bin/python3 - "$tmp" "$ROUNDS" <<'PY'
import sys
tmp, rounds = sys.argv[1], int(sys.argv[2])
def read(sysname):
    best, check = {}, {}
    for r in range(1, rounds + 1):
        for line in open(f"{tmp}/{sysname}.{r}"):
            name, t, c = line.split()
            best[name] = min(best.get(name, float("inf")), float(t))
            check[name] = c
    return best, check
lin, lc = read("linux")
win, wc = read("wine")
print(f"{'row':24} {'Linux s':>10} {'Wine s':>10} {'Wine/Linux':>10}  same numbers")
for name in lin:
    same = "yes" if abs(float(lc[name]) - float(wc[name])) <= 1e-9 * max(1.0, abs(float(lc[name]))) else f"NO ({lc[name]} / {wc[name]})"
    print(f"{name:24} {lin[name]:10.4f} {win[name]:10.4f} {win[name] / lin[name]:10.2f}  {same}")
PY
