#!/usr/bin/env bash
# Installs the build into a temporary prefix, then builds a consumer with
# pkg-config and with find_package(libblend), and runs both; then moves the
# prefix (to a folder whose name has a space) and renders and batches with
# the installed blendtool.
set -euo pipefail
build=$1; src=$2
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
cmake --install "$build" --prefix "$tmp/prefix" >/dev/null
export PKG_CONFIG_PATH="$tmp/prefix/lib/pkgconfig:$tmp/prefix/lib/x86_64-linux-gnu/pkgconfig"
test "$(pkg-config --modversion libblend)" = "0.1.0"
cc -std=c11 -Wall -Werror -o "$tmp/pc" "$src/consumer.c" $(pkg-config --cflags --libs libblend) \
   -Wl,-rpath,"$(pkg-config --variable=libdir libblend)"
"$tmp/pc"
cmake -S "$src" -B "$tmp/cm" -DCMAKE_PREFIX_PATH="$tmp/prefix" >/dev/null
cmake --build "$tmp/cm" >/dev/null
"$tmp/cm/consumer_shared"
"$tmp/cm/consumer_static"
# only the public API is exported from the shared object
bad=$(nm -D --defined-only "$tmp"/prefix/lib*/libblend.so* 2>/dev/null | awk '{print $3}' | grep -v '^lb_' | grep -v '^_' || true)
if [ -n "$bad" ]; then echo "unexpected exported symbols: $bad" >&2; exit 1; fi
soname=$(objdump -p "$tmp"/prefix/lib*/libblend.so.0.1.0 2>/dev/null | awk '/SONAME/{print $2}')
test "$soname" = "libblend.so.0"
echo "install: pkg-config and find_package consumers OK, soname $soname"

# blendtool from the installed prefix, copied elsewhere and the original
# removed: libblend.so through $ORIGIN, the image module and libblend.inc
# relative to the executable; no path of the source or build tree inside
mv "$tmp/prefix" "$tmp/moved prefix"
bt="$tmp/moved prefix/bin/blendtool"
for f in "$bt" "$tmp/moved prefix"/lib*/libblend.so.0.1.0; do
  if grep -aqF -e "$src" -e "$build" "$f"; then echo "$f holds a path of this tree" >&2; exit 1; fi
done
scene="$src/../../scenes/default.json"
cd "$tmp"
# (POV-Ray splits its command line at spaces: the prefix and TMPDIR hold one)
mkdir "$tmp/tmp dir"
env -u LIBBLEND_POVRAY_INCLUDE -u LIBBLEND_IMAGEIO TMPDIR="$tmp/tmp dir" "$bt" render "$scene" \
  -o "$tmp/moved.png" --width 48 --height 36 --quality 2 2>"$tmp/render.log" \
  || { cat "$tmp/render.log" >&2; exit 1; }
test -z "$(ls -A "$tmp/tmp dir")"
test -s "$tmp/moved.png"
cat > "$tmp/job.json" <<JOB
{"format": "libblend-job", "version": 1, "name": "moved", "scene": "$scene",
 "outputs": {"image": {"width": 48, "height": 36, "quality": 2}}, "output_dir": "$tmp/out"}
JOB
env -u LIBBLEND_POVRAY_INCLUDE -u LIBBLEND_IMAGEIO "$bt" batch "$tmp/job.json" >/dev/null 2>"$tmp/batch.log" \
  || { cat "$tmp/batch.log" >&2; exit 1; }
test -s "$tmp/out/moved_0000.png"
# $LIBBLEND_POVRAY_INCLUDE overrides: a folder without the include is named in the message
mkdir "$tmp/empty"
if LIBBLEND_POVRAY_INCLUDE="$tmp/empty" "$bt" render "$scene" -o "$tmp/no.png" --width 8 --height 6 \
     2>"$tmp/err.log"; then echo "render without libblend.inc succeeded" >&2; exit 1; fi
grep -qF "$tmp/empty/libblend.inc" "$tmp/err.log"
test ! -e "$tmp/no.png"
cp "$tmp/moved prefix/share/libblend/povray/libblend.inc" "$tmp/empty/"
LIBBLEND_POVRAY_INCLUDE="$tmp/empty" "$bt" render "$scene" -o "$tmp/yes.png" --width 8 --height 6 \
  --quality 2 2>/dev/null
test -s "$tmp/yes.png"
echo "install: blendtool renders and batches from a moved prefix; LIBBLEND_POVRAY_INCLUDE overrides"
