#!/usr/bin/env bash
# Runs the scene fuzzer for a bounded time, starting from the shipped scenes.
# usage: run_fuzz.sh FUZZER SOURCE_DIR WORK_DIR SECONDS
set -euo pipefail
FUZZER=$1
SRC=$2
WORK=$3
SECONDS_MAX=$4
rm -rf "$WORK"
mkdir -p "$WORK/corpus" "$WORK/artifacts"
cp "$SRC"/scenes/*.json "$SRC"/tests/data/scenes/*.json "$WORK/corpus/"
# -timeout: one input may not take more than 10 s; -rss_limit_mb: nor 2 GB
exec "$FUZZER" "$WORK/corpus" -dict="$SRC/tests/fuzz/scene.dict" \
  -max_total_time="$SECONDS_MAX" -timeout=10 -rss_limit_mb=2048 -max_len=65536 \
  -artifact_prefix="$WORK/artifacts/" -print_final_stats=1
