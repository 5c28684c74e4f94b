#!/usr/bin/env bash
# The JSON library libblend links statically, built from Debian's own source
# package, so that libblend.so (and the add-on and SDK that carry it) needs
# no JSON library at run time:
#
#   third-party.sh DIR [PLATFORM]
#       build cJSON for PLATFORM (linux-x64, the default, or windows-x64)
#       into DIR (DIR/include, DIR/lib/libcjson.a; for windows-x64 also
#       cmocka, which the cross-compiled tests use); a second run with the
#       same recipe does nothing
#
# Debian ships no archive of cJSON (libcjson-dev has no .a at all), so it is
# built here: the source packages of the Debian release this machine runs
# (Debian's patches applied, as in its own binary packages) are fetched with
# `apt-get source` through a private source list and private apt state under
# DIR/apt: the system's apt configuration is not touched and no root is
# needed. Objects are compiled position independent with hidden visibility
# (nothing of them is exported from libblend.so) and with
# libblend/src/common/glibc_compat.h in front, so that they bind to the same
# old glibc symbol versions as libblend itself (docs/portability.md).
#
# The result is built in DIR.tmp.PID and renamed into place when complete: an
# interrupted run leaves nothing half made. CMake runs this script at
# configure time when DIR has no archives (LIBBLEND_BUNDLED_JSON, default ON).
set -euo pipefail
[ $# -eq 1 ] || [ $# -eq 2 ] || {
  echo "usage: third-party.sh DIR [linux-x64|windows-x64]" >&2
  exit 2
}
DIR=$1
PLATFORM=${2:-linux-x64}
HERE=$(cd "$(dirname "$0")/.." && pwd)
COMPAT="$HERE/libblend/src/common/glibc_compat.h"
case "$PLATFORM" in
linux-x64)
  PACKAGES=(cjson)
  CC=gcc
  AR=ar
  CFLAGS_TP="-O2 -g0 -fPIC -fvisibility=hidden -include $COMPAT -DLB_GLIBC_BASELINE=1"
  CMAKE_CROSS=()
  ;;
windows-x64)
  PACKAGES=(cjson cmocka)
  CC=x86_64-w64-mingw32-gcc-posix
  AR=x86_64-w64-mingw32-ar
  # cJSON marks its functions dllexport on Windows unless told otherwise
  CFLAGS_TP="-O2 -g0 -DCJSON_HIDE_SYMBOLS"
  CMAKE_CROSS=(-DCMAKE_TOOLCHAIN_FILE="$HERE/cmake/mingw-w64-x86_64.cmake")
  command -v "$CC" >/dev/null || {
    echo "third-party: $CC is missing (Debian package gcc-mingw-w64-x86-64)" >&2
    exit 1
  }
  ;;
*)
  echo "third-party: unknown platform $PLATFORM; allowed: linux-x64, windows-x64" >&2
  exit 2
  ;;
esac

die() {
  echo "third-party: $*" >&2
  exit 1
}

# The stamp names what the archives were built from: the source versions are
# only known after the download, so the flags and this script's own hash are
# checked first (a changed script or compat header rebuilds).
recipe=$( (cat "$0" "$COMPAT" "$HERE/cmake/mingw-w64-x86_64.cmake"; echo "$PLATFORM") | sha256sum | cut -c1-16)
if [ -f "$DIR/.stamp" ] && grep -qx "recipe $recipe" "$DIR/.stamp"; then
  exit 0
fi

# The Debian mirror and release this machine already uses.
mirror=$(bash "$HERE/scripts/debian-mirror.sh")
# shellcheck disable=SC1091
suite=$(. /etc/os-release && echo "${VERSION_CODENAME:-}")
[ -n "$suite" ] || die "cannot tell the Debian release from /etc/os-release"
command -v dpkg-source >/dev/null || die "dpkg-source is missing (Debian package dpkg-dev)"
command -v cmake >/dev/null || die "cmake is missing"

mkdir -p "$(dirname "$DIR")"
TMP="$DIR.tmp.$$"
trap 'rm -rf "$TMP"' EXIT
trap 'exit 130' INT TERM
rm -rf "$TMP"
mkdir -p "$TMP"/{apt/lists/partial,apt/cache/archives/partial,src,include,lib}
printf 'deb-src %s %s main\ndeb-src %s %s-updates main\n' "$mirror" "$suite" "$mirror" "$suite" \
  >"$TMP/apt/sources.list"
APT=(apt-get -q -o "Dir::Etc::SourceList=$TMP/apt/sources.list" -o Dir::Etc::SourceParts=/dev/null
  -o "Dir::State::Lists=$TMP/apt/lists" -o "Dir::Cache=$TMP/apt/cache"
  -o APT::Sandbox::User=root)
echo "third-party: fetching ${PACKAGES[*]} source packages ($suite, $mirror)"
"${APT[@]}" update >"$TMP/apt.log" 2>&1 || {
  cat "$TMP/apt.log" >&2
  die "apt-get update of the private source list failed"
}
(cd "$TMP/src" && "${APT[@]}" source --download-only "${PACKAGES[@]}") >>"$TMP/apt.log" 2>&1 || {
  cat "$TMP/apt.log" >&2
  die "apt-get source ${PACKAGES[*]} failed"
}
for dsc in "$TMP"/src/*.dsc; do
  (cd "$TMP/src" && dpkg-source -x "$(basename "$dsc")") >>"$TMP/apt.log" 2>&1 ||
    die "dpkg-source -x $(basename "$dsc") failed"
done
versions=$(cd "$TMP/src" && ls -- *.dsc | sed 's/\.dsc$//' | tr '\n' ' ')

# cJSON: one source file.
cj=$(find "$TMP/src" -maxdepth 1 -type d -name 'cjson-*' | head -1)
[ -n "$cj" ] || die "no cjson source folder"
# shellcheck disable=SC2086
$CC $CFLAGS_TP -std=c89 -c "$cj/cJSON.c" -o "$TMP/cJSON.o"
"$AR" rcs "$TMP/lib/libcjson.a" "$TMP/cJSON.o"
mkdir -p "$TMP/include/cjson"
cp "$cj/cJSON.h" "$TMP/include/cjson/"

for f in "$cj/LICENSE"; do
  cp "$f" "$TMP/LICENSE.$(basename "$(dirname "$f")" | cut -d- -f1)"
done

# cmocka (windows-x64 only: the tests' framework; Linux uses Debian's).
if [[ " ${PACKAGES[*]} " == *" cmocka "* ]]; then
  cm=$(find "$TMP/src" -maxdepth 1 -type d -name 'cmocka-*' | head -1)
  [ -n "$cm" ] || die "no cmocka source folder"
  cmake -S "$cm" -B "$TMP/cmocka-build" -G Ninja -DCMAKE_BUILD_TYPE=Release "${CMAKE_CROSS[@]}" \
    -DCMAKE_C_FLAGS="$CFLAGS_TP" -DBUILD_SHARED_LIBS=OFF -DWITH_STATIC_LIB=ON \
    -DWITH_EXAMPLES=OFF -DUNIT_TESTING=OFF -DPICKY_DEVELOPER=OFF \
    -DCMAKE_INSTALL_PREFIX="$TMP/cmocka-install" >>"$TMP/build.log" 2>&1 ||
    { cat "$TMP/build.log" >&2; die "cmocka configure failed"; }
  cmake --build "$TMP/cmocka-build" >>"$TMP/build.log" 2>&1 &&
    cmake --install "$TMP/cmocka-build" >>"$TMP/build.log" 2>&1 ||
    { cat "$TMP/build.log" >&2; die "cmocka build failed"; }
  cp "$(find "$TMP/cmocka-install" -name 'libcmocka-static.a' | head -1)" "$TMP/lib/libcmocka.a"
  cp "$TMP/cmocka-install/include/"cmocka*.h "$TMP/include/"
  cp "$cm/COPYING" "$TMP/LICENSE.cmocka"
fi

printf 'recipe %s\nsources %s\n' "$recipe" "$versions" >"$TMP/.stamp"
rm -rf "$TMP"/{apt,src,cmocka-build,cmocka-install,cJSON.o,apt.log,build.log}
rm -rf "$DIR"
mv "$TMP" "$DIR"
trap - EXIT
echo "third-party: built $versions into $DIR"
