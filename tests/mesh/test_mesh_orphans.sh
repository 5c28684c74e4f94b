#!/bin/sh
# The orphan path (tests/mesh/test_mesh_orphans.c): the orphan build and the
# library must print the same line for every scene (vertex and triangle
# counts, hash of the triangles), and each passes its own checks.
# usage: test_mesh_orphans.sh ORPHAN_BUILD REFERENCE_BUILD SCENE...
set -eu
orphans=$1 ref=$2
shift 2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT INT TERM
"$orphans" "$@" >"$tmp/orphans"
"$ref" "$@" >"$tmp/ref"
if ! cmp -s "$tmp/orphans" "$tmp/ref"; then
    echo "FAIL: the orphan build's meshes differ from the library's:"
    diff "$tmp/ref" "$tmp/orphans" || true
    exit 1
fi
echo "test_mesh_orphans: $(wc -l <"$tmp/ref") scenes, the same meshes through the orphan path"
