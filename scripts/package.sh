#!/usr/bin/env bash
# Builds libblend's packages into dist/ (or $LIBBLEND_DIST):
#
#   libblend-VERSION-linux-x64.zip        Blender 4.2+ extension, Linux x64
#   libblend-VERSION-windows-x64.zip      Blender 4.2+ extension, Windows x64
#   libblend_blender-VERSION-legacy-linux-x64.zip
#                                         the add-on for Blender 3.x
#                                         (Preferences > Add-ons > Install)
#   libblend-sdk-VERSION-linux-x64.tar.gz blendtool, libblend.so/.a, headers,
#                                         pkg-config and CMake files,
#                                         libblend.inc, the image and
#                                         OpenVDB modules;
#                                         relocatable
#   libblend-sdk-VERSION-windows-x64.zip  libblend.dll, its import library,
#                                         libblend.a, headers, CMake files
#
#   bash scripts/package.sh                 configure and build both systems
#                                           (build-package-linux,
#                                           build-package-windows), then pack
#   bash scripts/package.sh --builds LINUX_BUILD WINDOWS_BUILD
#                                           pack from existing Release builds
#                                           (the test command does this)
#
# The extensions are validated and built by Blender 4.3's own `extension
# validate` and `extension build --split-platforms` in the Debian 13 root
# (scripts/debian-root.sh trixie-blender4), one source folder per platform
# holding only that platform's library, its manifest's `platforms` set to
# it. dist/ is replaced only when every package was made (built in
# dist.partial first). tests/packaging/test_packages.sh opens each package
# as a user would.
set -euo pipefail
cd "$(dirname "$0")/.."
SRC=$(pwd)
VERSION=$(sed -n 's/^project(libblend VERSION \([0-9.]*\).*/\1/p' CMakeLists.txt)
[ -n "$VERSION" ] || {
  echo "package: no version in CMakeLists.txt" >&2
  exit 1
}
DIST=${LIBBLEND_DIST:-$SRC/dist}
die() {
  echo "package: $*" >&2
  exit 1
}

if [ "${1:-}" = "--builds" ]; then
  [ $# -eq 3 ] || die "usage: package.sh [--builds LINUX_BUILD WINDOWS_BUILD]"
  lin=$(cd "$2" && pwd)
  win=$(cd "$3" && pwd)
else
  [ $# -eq 0 ] || die "usage: package.sh [--builds LINUX_BUILD WINDOWS_BUILD]"
  lin=$SRC/build-package-linux
  win=$SRC/build-package-windows
  # blendtool is linked against Debian 11's C library (runs on glibc 2.28+)
  bash scripts/debian-root.sh bullseye-base ensure >/dev/null
  cmake -S . -B "$lin" -G Ninja -DCMAKE_BUILD_TYPE=Release -DLIBBLEND_TESTS=OFF -DLIBBLEND_BENCH=OFF \
    -DLIBBLEND_TOOLS_SYSROOT="$(bash scripts/debian-root.sh bullseye-base path)"
  cmake --build "$lin"
  cmake -S . -B "$win" -G Ninja -DCMAKE_BUILD_TYPE=Release -DLIBBLEND_TESTS=OFF \
    -DLIBBLEND_BENCH=OFF -DCMAKE_TOOLCHAIN_FILE=cmake/mingw-w64-x86_64.cmake
  cmake --build "$win"
fi
so=$(readlink -f "$lin/libblend/libblend.so")
dll=$win/libblend/libblend.dll
addon=$lin/blender_addon/libblend_blender
legacy=$lin/blender_addon/libblend_blender-$VERSION.zip
for f in "$so" "$dll" "$addon/__init__.py" "$legacy"; do
  [ -e "$f" ] || die "$f is missing: build both systems first (Release)"
done
grep -q '^LIBBLEND_TOOLS_SYSROOT:PATH=.' "$lin/CMakeCache.txt" ||
  die "$lin links blendtool against this machine's C library (no LIBBLEND_TOOLS_SYSROOT): the SDK's blendtool would not run on an older Linux"
grep -q 'LIBBLEND_BUNDLED_JSON:BOOL=ON' "$lin/CMakeCache.txt" ||
  die "$lin links the shared JSON libraries (LIBBLEND_BUNDLED_JSON=OFF): its libblend.so is not portable"

stage=$(mktemp -d /tmp/libblend-package.XXXXXX)
trap 'rm -rf "$stage" "$DIST.partial"' EXIT
trap 'exit 130' INT TERM
rm -rf "$DIST.partial"
mkdir -p "$DIST.partial"
bash scripts/debian-root.sh trixie-blender4 ensure >/dev/null

# the Blender 4.2+ extensions, one per platform
for plat in linux-x64 windows-x64; do
  d=$stage/ext-$plat/libblend
  mkdir -p "$d" "$stage/out-$plat"
  cp -r "$addon/." "$d/"
  rm -rf "$d/lib" "$d/__pycache__"
  mkdir -p "$d/lib"
  if [ "$plat" = linux-x64 ]; then
    cp "$so" "$d/lib/libblend.so"
  else
    cp "$dll" "$d/lib/libblend.dll"
  fi
  sed -i "s/^platforms = .*/platforms = [\"$plat\"]/" "$d/blender_manifest.toml"
  bash scripts/debian-root.sh trixie-blender4 run "$stage" -- bash -c '
    set -e
    blender -b --factory-startup --command extension validate "$1" >"$3/validate.log" 2>&1 ||
      { cat "$3/validate.log" >&2; exit 1; }
    blender -b --factory-startup --command extension build --split-platforms \
      --source-dir "$1" --output-dir "$2" >"$3/build.log" 2>&1 ||
      { cat "$3/build.log" >&2; exit 1; }
  ' _ "$d" "$stage/out-$plat" "$stage" || die "Blender could not validate or build the $plat extension"
  built=("$stage/out-$plat"/*.zip)
  [ "${#built[@]}" -eq 1 ] && [ -f "${built[0]}" ] ||
    die "extension build made ${#built[@]} files for $plat"
  mv "${built[0]}" "$DIST.partial/libblend-$VERSION-$plat.zip"
done

# the legacy add-on zip (Blender 3.x)
cp "$legacy" "$DIST.partial/libblend_blender-$VERSION-legacy-linux-x64.zip"

# the SDKs
sdk=libblend-sdk-$VERSION-linux-x64
cmake --install "$lin" --prefix "$stage/$sdk" >/dev/null
tar -C "$stage" --owner=0 --group=0 -czf "$DIST.partial/$sdk.tar.gz" "$sdk"
sdk=libblend-sdk-$VERSION-windows-x64
cmake --install "$win" --prefix "$stage/$sdk" >/dev/null
(cd "$stage" && /usr/bin/python3 -m zipfile -c "$DIST.partial/$sdk.zip" "$sdk")

rm -rf "$DIST"
mv "$DIST.partial" "$DIST"
trap - EXIT
rm -rf "$stage"
echo "package: $DIST"
(cd "$DIST" && ls -l --time-style=+ | awk 'NR > 1 {printf "  %9d  %s\n", $5, $NF}')
