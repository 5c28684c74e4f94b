#!/usr/bin/env bash
# libblend.so loads on a Linux that has neither this machine's glibc nor its
# JSON libraries (issue 29):
#  1. the build's libblend.so and the copy inside the add-on zip need nothing
#     beyond the C runtime (NEEDED: libc, libm, libpthread, libdl, the
#     loader), every symbol they import is a glibc one (so nothing can be
#     silently supplied by whatever else the host process loaded, as Blender's
#     FFmpeg loads libcjson), and no glibc symbol version is newer than 2.28
#     (the manylinux_2_28 policy: Blender's own builds, Rocky/Alma 8 farms);
#  2. in a Debian 11 root (glibc 2.31, the oldest release the mirror serves;
#     no libcjson1 or libjansson4 in it, scripts/debian-root.sh bullseye-base)
#     a C program compiled there against the public headers runs against the
#     zip's libblend.so (values against a closed form, threads, a closed mesh,
#     an atomic write), and the add-on's own ctypes binding, unzipped as a
#     user unzips it, loads the library in that root's Python 3.9 and
#     compiles and bounds the default scene.
#   test_portable_so.sh BUILD SRC ZIP
set -euo pipefail
build=$1 src=$2 zip=$3
tmp=$(mktemp -d /tmp/libblend-portable.XXXXXX)
trap 'rm -rf "$tmp"' EXIT
fail() {
  echo "test_portable_so: $*" >&2
  exit 1
}

check_so() {
  local so=$1 needed bad
  needed=$(objdump -p "$so" | awk '$1 == "NEEDED" {print $2}')
  bad=$(echo "$needed" | grep -vxE 'libc\.so\.6|libm\.so\.6|libpthread\.so\.0|libdl\.so\.2|ld-linux-x86-64\.so\.2' || true)
  [ -z "$bad" ] || fail "$so needs $(echo "$bad" | tr '\n' ' ')beyond the C runtime"
  # the newest glibc version any imported symbol asks for
  local newest
  newest=$(objdump -T "$so" | grep -o 'GLIBC_[0-9.]*' | sed 's/GLIBC_//' | sort -uV | tail -1)
  [ -n "$newest" ] || fail "$so: no glibc symbol versions at all (objdump -T)"
  if [ "$(printf '%s\n2.28\n' "$newest" | sort -V | tail -1)" != "2.28" ]; then
    fail "$so asks for GLIBC_$newest: $(objdump -T "$so" | grep -E "GLIBC_$newest[[:space:]]" | awk '{print $NF}' | tr '\n' ' ')(newer than 2.28)"
  fi
  # every undefined dynamic symbol comes from glibc (weak hooks aside)
  bad=$(objdump -T "$so" | awk '$0 ~ /\*UND\*/ && $0 !~ /GLIBC_/ && $2 != "w" {print $NF}')
  [ -z "$bad" ] || fail "$so imports symbols from outside glibc: $(echo "$bad" | tr '\n' ' ')"
  echo "$so: NEEDED $(echo "$needed" | tr '\n' ' ')newest GLIBC_$newest"
}

check_so "$(readlink -f "$build/libblend/libblend.so")"
mkdir -p "$tmp/user"
/usr/bin/python3 -m zipfile -e "$zip" "$tmp/user"
zso=$(find "$tmp/user" -name libblend.so -path '*/lib/*' | head -1)
[ -n "$zso" ] || fail "$zip holds no lib/libblend.so"
check_so "$zso"

root=$(bash "$src/scripts/debian-root.sh" bullseye-base path)
[ -f "$root/.libblend-root-ok" ] ||
  fail "no Debian 11 root at $root: run 'bash scripts/debian-root.sh bullseye-base ensure' (scripts/test.sh does)"
for p in libcjson1 libjansson4; do
  if chroot "$root" dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    fail "the Debian 11 root has $p: it could hide a missing JSON library"
  fi
done
mkdir -p "$tmp/out" "$tmp/lib"
zlib=$(dirname "$zso")
# the program links by the library's soname, as a developer's build would
ln -s "$zso" "$tmp/lib/$(objdump -p "$zso" | awk '$1 == "SONAME" {print $2}')"
bash "$src/scripts/debian-root.sh" bullseye-base run "$src" "$tmp" -- bash -c '
  set -euo pipefail
  src=$1 tmp=$2 zlib=$3
  echo "root: $(ldd --version | head -1)"
  gcc -std=c11 -O1 -Wall -Werror -I "$src/libblend/include" \
    -o "$tmp/consumer" "$src/tests/portability/old_glibc_consumer.c" \
    -L "$zlib" -l:libblend.so -lm -Wl,-rpath,"$tmp/lib"
  "$tmp/consumer" "$src/scenes/default.json" "$tmp/out"
  pkg=$(dirname "$zlib")
  python3 - "$pkg" "$src/scenes/default.json" <<PY
import sys
sys.path.insert(0, sys.argv[1])
import binding  # the add-on module, without Blender
lib = binding.load()
scene = lib.load_scene(sys.argv[2])
ev = scene.compile()
lo, hi = ev.bounds((-0.1, -0.1, -0.1), (0.1, 0.1, 0.1))
assert lo <= hi, (lo, hi)
print("python %d.%d: %s loaded libblend %d.%d.%d from %s, default scene bounds near 0: [%.4g, %.4g]"
      % (sys.version_info[:2] + (binding.platform_tag(),) + lib.version + (lib.path, lo, hi)))
PY
' _ "$src" "$tmp" "$zlib"
test -s "$tmp/out/default.ply" || fail "the mesh written in the Debian 11 root is missing"
echo "test_portable_so: OK"
