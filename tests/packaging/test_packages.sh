#!/usr/bin/env bash
# Every package scripts/package.sh made, opened as a user opens it:
#  - the Linux extension: installed by Blender 4.3's `extension install-file`
#    in the Debian 13 root (which has no libjansson4; see
#    scripts/debian-root.sh), enabled, a field meshed and edited, undo and
#    redo, saved and reopened, a frame rendered
#    (tests/blender/test_install_zip.py, as for the legacy zip);
#  - the legacy zip: installed into Blender 3.4 with Preferences > Add-ons >
#    Install (tests/blender/test_install_zip.py);
#  - the Windows extension: its manifest says windows-x64, it holds
#    lib/libblend.dll (the same bytes as the SDK's) and no .so;
#  - the Linux SDK tarball: unpacked into a folder whose name has a space,
#    a program built against it with CMake's find_package runs (shared and
#    static), and its blendtool
#    validates, meshes and renders the default scene; the same tarball
#    unpacked on a bare Debian 11 node (base system and POV-Ray only)
#    validates, meshes (the same bytes) and renders (POV-Ray's own PNG with
#    the libblend metadata, the same pixels);
#  - the Windows SDK zip: unpacked, a program cross-compiled against its
#    headers and import library runs under Wine with the DLL beside it.
#   test_packages.sh DIST SRC
set -euo pipefail
dist=$(cd "$1" && pwd)
src=$(cd "$2" && pwd)
version=$(sed -n 's/^project(libblend VERSION \([0-9.]*\).*/\1/p' "$src/CMakeLists.txt")
tmp=$(mktemp -d /tmp/libblend-packages.XXXXXX)
trap 'rm -rf "$tmp"' EXIT
fail() {
  echo "test_packages: $*" >&2
  exit 1
}
py=/usr/bin/python3
lext=$dist/libblend-$version-linux-x64.zip
wext=$dist/libblend-$version-windows-x64.zip
legacy=$dist/libblend_blender-$version-legacy-linux-x64.zip
lsdk=$dist/libblend-sdk-$version-linux-x64.tar.gz
wsdk=$dist/libblend-sdk-$version-windows-x64.zip
for f in "$lext" "$wext" "$legacy" "$lsdk" "$wsdk"; do
  [ -s "$f" ] || fail "$f is missing"
done

# what each extension holds and says
"$py" - "$lext" "$wext" <<'PY'
import sys, tomllib, zipfile
for path, plat, lib, other in ((sys.argv[1], "linux-x64", "lib/libblend.so", ".dll"),
                               (sys.argv[2], "windows-x64", "lib/libblend.dll", ".so")):
    z = zipfile.ZipFile(path)
    names = z.namelist()
    man = tomllib.loads(z.read("blender_manifest.toml").decode())
    assert man["platforms"] == [plat], (path, man["platforms"])
    assert lib in names, (path, "no " + lib)
    assert not [n for n in names if n.endswith(other)], (path, "holds another platform's library")
    assert "povray/libblend.inc" in names and "binding.py" in names, path
    print("%s: %s, %s, %d files" % (path.rsplit("/", 1)[-1], plat, lib, len(names)))
PY

# the Windows SDK: a consumer under Wine, with the DLL beside it
mkdir -p "$tmp/wsdk"
"$py" -m zipfile -e "$wsdk" "$tmp/wsdk"
w=$tmp/wsdk/libblend-sdk-$version-windows-x64
x86_64-w64-mingw32-gcc-posix -std=c11 -Wall -Werror -I "$w/include" -o "$tmp/wsdk/consumer.exe" \
  "$src/tests/install/consumer.c" "$w/lib/libblend.dll.a"
cp "$w/bin/libblend.dll" "$tmp/wsdk/"
out=$(bash "$src/scripts/wine-run.sh" "$tmp/wsdk/consumer.exe" | tr -d '\r')
want=$(echo "$version" | awk -F. '{print $1 * 10000 + $2 * 100 + $3}')
case "$out" in "$want "*) ;; *) fail "the Windows consumer printed '$out', not version $want first" ;; esac
echo "windows sdk: consumer under Wine printed: $out"
"$py" - "$wext" "$w/bin/libblend.dll" <<'PY'
import sys, zipfile
assert zipfile.ZipFile(sys.argv[1]).read("lib/libblend.dll") == open(sys.argv[2], "rb").read(), \
    "the extension's DLL differs from the SDK's"
PY

# the Linux SDK, unpacked where a user might put it
mkdir -p "$tmp/my tools"
tar -C "$tmp/my tools" -xzf "$lsdk"
l="$tmp/my tools/libblend-sdk-$version-linux-x64"
# a CMake project finds it (find_package; pkg-config is checked by
# test_install: its output cannot hold a folder name with a space)
cmake -S "$src/tests/install" -B "$tmp/lconsumer" -DCMAKE_PREFIX_PATH="$l" >/dev/null
cmake --build "$tmp/lconsumer" >/dev/null
out=$("$tmp/lconsumer/consumer_shared")
case "$out" in "$want "*) ;; *) fail "the Linux consumer printed '$out'" ;; esac
"$tmp/lconsumer/consumer_static" >/dev/null
bt="$l/bin/blendtool"
cd "$tmp"
env -u LIBBLEND_POVRAY_INCLUDE -u LIBBLEND_IMAGEIO "$bt" validate "$src/scenes/default.json" >/dev/null
env -u LIBBLEND_POVRAY_INCLUDE -u LIBBLEND_IMAGEIO "$bt" mesh "$src/scenes/default.json" \
  -o "$tmp/default.ply" --resolution 32 >/dev/null
env -u LIBBLEND_POVRAY_INCLUDE -u LIBBLEND_IMAGEIO "$bt" render "$src/scenes/default.json" \
  -o "$tmp/default.png" --width 64 --height 48 --quality 2 2>"$tmp/render.log" ||
  { cat "$tmp/render.log" >&2; fail "blendtool render from the SDK failed"; }
[ -s "$tmp/default.ply" ] && [ -s "$tmp/default.png" ] || fail "the SDK's blendtool wrote no mesh or image"
echo "linux sdk: consumer, blendtool validate/mesh/render from '$l'"

# The SDK's blendtool on a bare farm node: Debian 11 (glibc 2.31) with only
# the base system and POV-Ray (scripts/debian-root.sh bullseye-povray), no
# OpenImageIO, no libxxhash, no JSON library. First what it links: nothing
# beyond the C runtime, zlib and libblend.so, no symbol newer than glibc 2.28.
needed=$(objdump -p "$bt" | awk '/NEEDED/ {print $2}' | sort | tr '\n' ' ')
[ "$needed" = "libblend.so.0 libc.so.6 libdl.so.2 libm.so.6 libz.so.1 " ] ||
  fail "the SDK's blendtool needs: $needed"
newest=$(objdump -T "$bt" | grep -o 'GLIBC_2\.[0-9.]*' | sort -V | tail -1)
[ "$(printf '%s\nGLIBC_2.28\n' "$newest" | sort -V | tail -1)" = GLIBC_2.28 ] ||
  fail "the SDK's blendtool needs $newest (allowed: GLIBC_2.28 or older)"
node=$(bash "$src/scripts/debian-root.sh" bullseye-povray path)
mkdir -p "$tmp/farm node"
tar -C "$tmp/farm node" -xzf "$lsdk"
cp "$src/scenes/default.json" "$tmp/farm node/"
nb="$tmp/farm node/libblend-sdk-$version-linux-x64/bin/blendtool"
on_node() {
  bash "$src/scripts/debian-root.sh" bullseye-povray run "$tmp" -- env -C "$tmp/farm node" "$@"
}
on_node "$nb" validate default.json >"$tmp/node-validate.log" 2>&1 ||
  { cat "$tmp/node-validate.log" >&2; fail "blendtool validate on the Debian 11 node failed"; }
on_node "$nb" mesh default.json -o node.ply --resolution 32 >/dev/null 2>"$tmp/node-mesh.log" ||
  { cat "$tmp/node-mesh.log" >&2; fail "blendtool mesh on the Debian 11 node failed"; }
# the same mesh, byte for byte, as the same blendtool makes on this machine
env -u LIBBLEND_POVRAY_INCLUDE -u LIBBLEND_IMAGEIO "$bt" mesh "$src/scenes/default.json" \
  -o "$tmp/here.ply" --resolution 32 >/dev/null
cmp "$tmp/farm node/node.ply" "$tmp/here.ply" || fail "the node's mesh differs from this machine's"
# one render thread: POV-Ray's threads share out the area light's jitter
# differently from run to run
on_node "$nb" render default.json -o node.png --width 80 --height 60 --threads 1 \
  >/dev/null 2>"$tmp/node-render.log" ||
  { cat "$tmp/node-render.log" >&2; fail "blendtool render on the Debian 11 node failed"; }
grep -q "note: cannot load the image module" "$tmp/node-render.log" ||
  fail "the node's render does not say that it wrote POV-Ray's own PNG"
on_node "$nb" render default.json -o node.exr --width 8 --height 6 >/dev/null \
  2>"$tmp/node-exr.log" && fail "an EXR render without OpenImageIO succeeded"
grep -q "OpenEXR needs the image module" "$tmp/node-exr.log" || fail "no clear message for EXR on the node"
[ ! -e "$tmp/farm node/node.exr" ] || fail "the refused EXR render left a file"
# no OpenVDB on the node: blendtool vdb says what to install, exit 1, no file
on_node "$nb" vdb default.json -o node.vdb --resolution 16 >/dev/null 2>"$tmp/node-vdb.log" &&
  fail "blendtool vdb without OpenVDB succeeded"
grep -q "cannot load the OpenVDB module.*install OpenVDB 10" "$tmp/node-vdb.log" ||
  { cat "$tmp/node-vdb.log" >&2; fail "no clear message for vdb on the node"; }
[ ! -e "$tmp/farm node/node.vdb" ] || fail "the refused vdb left a file"
# here (OpenVDB installed) the SDK's blendtool finds its own module at
# lib/libblend/liblbvdb.so; OpenVDB reads the level set back
env -u LIBBLEND_VDB "$bt" vdb "$src/scenes/default.json" -o "$tmp/sdk.vdb" --resolution 16 -q ||
  fail "the SDK's blendtool vdb failed here"
/usr/bin/python3 -c 'import sys, pyopenvdb as v; g = v.read(sys.argv[1], "surface")
assert g.gridClass == v.GridClass.LEVEL_SET and g.activeVoxelCount() > 100' "$tmp/sdk.vdb" ||
  fail "the SDK's .vdb is not a level set OpenVDB reads"
# what the node wrote, read here by OpenImageIO: the libblend metadata, no
# time stamp, and the pixels of this machine's render (through the image
# module) within a small threshold (Debian 11 has POV-Ray 3.7.0.8, here 3.7.0.10)
env -u LIBBLEND_POVRAY_INCLUDE -u LIBBLEND_IMAGEIO "$bt" render "$src/scenes/default.json" \
  -o "$tmp/here.png" --width 80 --height 60 --threads 1 2>/dev/null
info=$(oiiotool --info -v "$tmp/farm node/node.png")
for k in scene_hash version render parameters; do
  grep -q "libblend:$k" <<<"$info" || fail "the node's PNG lacks libblend:$k"
done
grep -qi "DateTime\|Render Date\|Software" <<<"$info" && fail "the node's PNG keeps POV-Ray's time stamp"
"$bt" compare "$tmp/here.png" "$tmp/farm node/node.png" --fail 0.02 --fail-percent 0.5 ||
  fail "the node's image differs from this machine's"
echo "linux sdk on a bare Debian 11 node (glibc 2.31, POV-Ray, no OpenImageIO or OpenVDB): validate, the same mesh, render, vdb refused ($newest); the SDK's vdb here"

# the legacy zip in Blender 3.4, as a user installs it
env BLENDER_USER_SCRIPTS="$tmp/b3-user" PYTHONDONTWRITEBYTECODE=1 blender -b --factory-startup \
  --python-exit-code 1 --python "$src/tests/blender/test_install_zip.py" -- "$legacy" \
  >"$tmp/b3.log" 2>&1 || { tail -30 "$tmp/b3.log" >&2; fail "the legacy zip in Blender 3.4"; }
echo "legacy zip: installed and used in Blender 3.4"

# the Linux extension in Blender 4.3, installed by Blender's own command
mkdir -p "$tmp/b4"
bash "$src/scripts/debian-root.sh" trixie-blender4 run "$src" "$dist" "$tmp" -- bash -c '
  set -e
  export BLENDER_USER_RESOURCES=$1/user PYTHONDONTWRITEBYTECODE=1
  blender -b --factory-startup --command extension install-file -r user_default -e "$2"
  blender -b --factory-startup --python-exit-code 1 --python "$3/tests/blender/test_install_zip.py" \
    -- "$2" bl_ext.user_default.libblend
' _ "$tmp/b4" "$lext" "$src" >"$tmp/b4.log" 2>&1 ||
  { tail -40 "$tmp/b4.log" >&2; fail "the Linux extension in Blender 4.3"; }
grep -q '^test_install_zip: installed from' "$tmp/b4.log" || { tail -20 "$tmp/b4.log" >&2; fail "Blender 4.3 did not finish the checks"; }
echo "linux extension: installed with extension install-file and used in Blender 4.3"
echo "test_packages: OK"
