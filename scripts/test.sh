#!/usr/bin/env bash
# The whole test suite: install what is missing, then a Release build and a
# sanitizer (ASan + UBSan) build, each built from scratch and run by ctest.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
JOBS=$(nproc)
for cfg in "build-release:-DCMAKE_BUILD_TYPE=Release" \
           "build-asan:-DCMAKE_BUILD_TYPE=RelWithDebInfo -DLIBBLEND_SANITIZE=ON"; do
  dir=${cfg%%:*}
  flags=${cfg#*:}
  echo "== $dir ($flags)"
  # shellcheck disable=SC2086
  cmake -S . -B "$dir" -G Ninja $flags
  cmake --build "$dir" -j "$JOBS"
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    ctest --test-dir "$dir" --output-on-failure -j "$JOBS"
done
