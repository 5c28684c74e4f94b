#!/usr/bin/env bash
# Builds docs/gallery/ (docs/gallery/README.md): every job in
# docs/gallery/jobs/ rendered by blendtool batch with POV-Ray (480 x 360 per
# panel, antialiased, libblend's mesh at the job's resolution) and assembled
# by OpenImageIO into one labelled contact sheet per figure; the panels and
# the sheet are copied to docs/gallery/NAME/.
# The field sections of docs/gallery/sections.json go to docs/gallery/sections/.
# tests/gallery/test_gallery.py regenerates them (panels at half size) and compares.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build-release -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build-release -j "$(nproc)" --target blendtool >/dev/null
for job in docs/gallery/jobs/*.json; do
  name=$(basename "$job" .json)
  out=build-release/gallery/$name
  build-release/tools/blendtool batch "$job" --threads "$(nproc)" --log "$out.log"
  rm -rf "docs/gallery/$name.tmp"
  mkdir -p "docs/gallery/$name.tmp"
  cp "$out"/*.png "docs/gallery/$name.tmp/"
  rm -rf "docs/gallery/$name"
  mv "docs/gallery/$name.tmp" "docs/gallery/$name"
  echo "gallery: docs/gallery/$name/${name}_sheet.png"
done
# the field sections (2D plots of the contours, docs/gallery/sections.json)
rm -rf docs/gallery/sections.tmp
/usr/bin/python3 scripts/gallery_sections.py build-release/tools/blendtool . docs/gallery/sections.tmp
rm -rf docs/gallery/sections
mv docs/gallery/sections.tmp docs/gallery/sections
