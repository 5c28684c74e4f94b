#!/usr/bin/env bash
# The main job on the built-in default scene (scenes/default.json): install
# what is missing, build, validate every shipped scene, describe the default
# one, evaluate its field and gradient at points along a line through it,
# mesh it and render it. One line per stage on the terminal; what the
# install and the build print goes to a log ($BUILD/run-default.log), whose
# end is shown when a stage fails. Outputs: $BUILD/default.ply,
# $BUILD/default.png. BUILD is build-release (LIBBLEND_BUILD sets another).
set -euo pipefail
cd "$(dirname "$0")/.."
build=${LIBBLEND_BUILD:-build-release}
mkdir -p "$build"
log=$build/run-default.log
: >"$log"

stage() { # LABEL COMMAND...: run it into the log, one line here
  local label=$1 t0=$SECONDS
  shift
  printf '%-40s' "$label"
  if "$@" >>"$log" 2>&1; then
    echo " ok ($((SECONDS - t0)) s)"
  else
    echo " FAILED"
    echo "run-default: \"$label\" failed; the end of its output ($log):" >&2
    tail -n 25 "$log" >&2
    exit 1
  fi
}

stage "install what is missing" bash scripts/install-deps.sh
stage "configure ($build)" cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release
stage "build" cmake --build "$build" -j "$(nproc)"
bt=$build/tools/blendtool
stage "validate the $(ls scenes/*.json | wc -l) shipped scenes" "$bt" validate --quiet scenes/*.json
echo
"$bt" info scenes/default.json | sed -n '2,5p'
echo
echo "the field and its gradient along the y axis, through the cube and the blended super-ellipsoid:"
printf '%8s %8s %8s   %12s %12s %12s %12s\n' x y z value gx gy gz
points=$(for y in -1.2 -0.9 0 0.9 1.0 1.1 1.35 1.9 2.1; do echo "0 $y 0"; done)
paste -d ' ' <(echo "$points") <(echo "$points" | "$bt" eval scenes/default.json) |
  while read -r x y z v gx gy gz; do
    printf '%8s %8s %8s   %12.6g %12.6g %12.6g %12.6g\n' "$x" "$y" "$z" "$v" "$gx" "$gy" "$gz"
  done
echo
stage "mesh at 256 cells" "$bt" mesh scenes/default.json -o "$build/default.ply" --resolution 256 --quiet
stage "render with POV-Ray (320 x 240)" "$bt" render scenes/default.json -o "$build/default.png" \
  --width 320 --height 240 --quality 4 --antialias --quiet
addon=$(ls "$build"/blender_addon/libblend_blender-*.zip 2>/dev/null | head -n 1)
cat <<NEXT

picture: $build/default.png
mesh:    $build/default.ply
next:
  - open the mesh in Blender or MeshLab, or the picture in any image viewer
  - Blender 3.x: Edit > Preferences > Add-ons > Install..., pick
    ${addon:-the zip in $build/blender_addon}, tick libblend, then Add > libblend > libblend Field
    (Blender 4.2 and later: blender_addon_c/README.md, "Install")
  - your own scene: copy scenes/default.json, change it (docs/scene-format.md), then
    $bt render YOURS.json -o yours.png --antialias --quiet
  - a sweep on a farm: $bt batch scenes/jobs/bernhardt-drop-sweep.json (docs/batch.md)
NEXT
