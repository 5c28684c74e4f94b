#!/usr/bin/env bash
# Behaviour unchanged by a refactoring: every shipped scene's POV-Ray export
# and its mesh (PLY at 128 cells, one thread) made by the working tree's
# blendtool and by the one of revision REV (default HEAD, built from a
# temporary `git worktree`) must be the same bytes. Run before each commit of
# a restructuring (docs/design.md); prints one line per scene that differs
# and exits 1 then.
#   bash scripts/check-unchanged.sh [REV]
set -euo pipefail
cd "$(dirname "$0")/.."
REV=${1:-HEAD}
# shellcheck source=scripts/revision-tree.sh
. "$PWD/scripts/revision-tree.sh"
revision_tree check-unchanged "$REV"
base=$tmp
build() { # SRC BUILD
  cmake -S "$1" -B "$2" -G Ninja -DCMAKE_BUILD_TYPE=Release -DLIBBLEND_TESTS=OFF \
    -DLIBBLEND_BENCH=OFF >/dev/null
  cmake --build "$2" --target blendtool >/dev/null
}
build "$base/tree" "$base/build-old"
build . build-unchanged
export LIBBLEND_POVRAY_INCLUDE=$PWD/povray_include
bad=0
n=0
for s in scenes/*.json; do
  name=$(basename "$s" .json)
  for side in old new; do
    bt=$base/build-old/tools/blendtool
    [ "$side" = new ] && bt=build-unchanged/tools/blendtool
    mkdir -p "$base/$side"
    "$bt" pov "$s" -o "$base/$side/$name.pov" 2>/dev/null || echo "pov failed" >"$base/$side/$name.pov"
    "$bt" mesh "$s" -o "$base/$side/$name.ply" --resolution 128 --threads 1 >/dev/null 2>&1 ||
      echo "mesh failed" >"$base/$side/$name.ply"
  done
  for ext in pov ply; do
    if ! cmp -s "$base/old/$name.$ext" "$base/new/$name.$ext"; then
      echo "check-unchanged: $s: the .$ext differs from $REV's"
      bad=1
    fi
  done
  n=$((n + 1))
done
[ "$bad" -eq 0 ] || exit 1
echo "check-unchanged: $n scenes, POV-Ray export and 128-cell PLY byte-identical to $REV"
