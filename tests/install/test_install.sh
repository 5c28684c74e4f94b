#!/usr/bin/env bash
# Installs the build into a temporary prefix, then builds a consumer with
# pkg-config and with find_package(libblend), and runs both.
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
