#!/usr/bin/env bash
# Debian roots for the tests, made with debootstrap, cached, and run with
# chroot in a private mount namespace:
#
#   debian-root.sh NAME ensure             make root NAME if it is not there yet
#                                          (cached: later runs only check it)
#   debian-root.sh NAME path               print the root's folder
#   debian-root.sh NAME run DIR... -- CMD  run CMD inside the root, with each DIR
#                                          of this machine bound at the same path
#
# The roots (NAME):
#   trixie-blender4  Debian 13 with its Blender 4.3 (Debian 12 ships only 3.4),
#                    numpy for the add-on, POV-Ray (the add-on's export is
#                    rendered) and libxxhash0 (blendtool, built on the host,
#                    runs inside). About 3 min and 1.8 GB the first time.
#                    Folder: $LIBBLEND_BLENDER4_ROOT or
#                    /var/cache/libblend/trixie-blender4.
#   bullseye-base    Debian 11 (glibc 2.31, the oldest release the mirror
#                    serves) with only the base system, Python and a C
#                    compiler: the portable libblend.so is loaded there
#                    (tests/portability). About 1 min the first time.
#                    Folder: $LIBBLEND_BULLSEYE_ROOT or
#                    /var/cache/libblend/bullseye-base. The test command's
#                    Release build links blendtool against its C library
#                    (tools/CMakeLists.txt, LIBBLEND_TOOLS_SYSROOT).
#   bullseye-povray  Debian 11 with only the base system and POV-Ray: a bare
#                    farm node, where the Linux SDK's blendtool validates,
#                    meshes and renders (tests/packaging). About 1.5 min the
#                    first time. Folder: $LIBBLEND_BULLSEYE_POVRAY_ROOT or
#                    /var/cache/libblend/bullseye-povray.
# No root has libjansson4; the bullseye ones have no libcjson1 either (in
# trixie-blender4 Blender's FFmpeg needs it through librist4), so nothing in
# them can supply a JSON library that libblend.so forgot to carry.
#
# A root is built in a sibling folder and renamed into place when complete,
# so an interrupted build leaves no half-made root behind (the next run
# starts over). Mounts are made in a private mount namespace (unshare), so
# they vanish with the command, even when it is killed. Needs root
# (debootstrap and chroot); debootstrap is installed on the host here,
# apt-get idempotent.
set -euo pipefail
NAME=${1:-}
case "$NAME" in
trixie-blender4)
  ROOT=${LIBBLEND_BLENDER4_ROOT:-/var/cache/libblend/trixie-blender4}
  SUITE=trixie
  PACKAGES=(blender python3-numpy libxxhash0 povray)
  ABSENT=(libjansson4)
  ;;
bullseye-base)
  ROOT=${LIBBLEND_BULLSEYE_ROOT:-/var/cache/libblend/bullseye-base}
  SUITE=bullseye
  PACKAGES=(python3 gcc libc6-dev)
  ABSENT=(libjansson4 libcjson1)
  ;;
bullseye-povray)
  ROOT=${LIBBLEND_BULLSEYE_POVRAY_ROOT:-/var/cache/libblend/bullseye-povray}
  SUITE=bullseye
  PACKAGES=(povray)
  ABSENT=(libjansson4 libcjson1 libopenimageio2.2)
  ;;
*)
  echo "usage: debian-root.sh trixie-blender4|bullseye-base|bullseye-povray ensure | path | run DIR... -- CMD..." >&2
  exit 2
  ;;
esac
shift
MARK="$ROOT/.libblend-root-ok"

# What proves the new root works (printed into its mark).
root_check() {
  case "$NAME" in
  trixie-blender4)
    run_in "$1" -- blender -b --factory-startup --version 2>/dev/null |
      awk '/^Blender/ {print "blender " $2; exit}'
    ;;
  bullseye-base)
    run_in "$1" -- ldd --version 2>/dev/null | awk 'NR == 1 {print "glibc " $NF}'
    ;;
  bullseye-povray)
    run_in "$1" -- povray --version 2>&1 | awk '/^POV-Ray/ {print "POV-Ray " $2; exit}'
    ;;
  esac
}

die() {
  echo "debian-root $NAME: $*" >&2
  exit 1
}

# The Debian mirror this machine already uses.
mirror() {
  bash "$(dirname "$0")/debian-mirror.sh"
}

# Packages of PACKAGES missing in root $1 (none: prints nothing).
missing_in() {
  local p
  for p in "${PACKAGES[@]}"; do
    chroot "$1" dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" ||
      echo "$p"
  done
}

# apt-get install the given packages into root $1 (log to $2).
install_in() {
  local r=$1 log=$2
  shift 2
  unshare --mount --propagation private bash -c '
    set -e
    r=$1; shift
    mount -t proc proc "$r/proc"
    chroot "$r" apt-get update -qq
    chroot "$r" env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "$@"
    chroot "$r" apt-get clean
  ' _ "$r" "$@" >>"$log" 2>&1 || { tail -20 "$log" >&2; die "installing $* in $r failed (log above)"; }
}

ensure() {
  if [ -f "$MARK" ]; then
    local miss
    miss=$(missing_in "$ROOT")
    if [ -n "$miss" ]; then  # the list grew since the root was made
      # shellcheck disable=SC2086
      echo "debian-root $NAME: adding to the cached root:" $miss
      # shellcheck disable=SC2086
      install_in "$ROOT" "$ROOT.log" $miss
      rm -f "$ROOT.log"
    fi
    local p present=()
    for p in "${ABSENT[@]}"; do
      chroot "$ROOT" dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" &&
        present+=("$p")
    done
    if [ "${#present[@]}" -gt 0 ]; then  # made when the list still had them
      echo "debian-root $NAME: removing from the cached root: ${present[*]}"
      chroot "$ROOT" env DEBIAN_FRONTEND=noninteractive apt-get purge -y -qq "${present[@]}" \
        >"$ROOT.log" 2>&1 || { tail -20 "$ROOT.log" >&2; die "removing ${present[*]} failed"; }
      rm -f "$ROOT.log"
    fi
    echo "debian-root $NAME: cached at $ROOT ($(cat "$MARK"))"
    return 0
  fi
  [ "$(id -u)" -eq 0 ] || die "making the root needs root (debootstrap, chroot)"
  if ! command -v debootstrap >/dev/null; then
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends debootstrap
  fi
  local tmp="$ROOT.partial"
  rm -rf "$tmp"
  mkdir -p "$tmp"
  trap 'rm -rf "$tmp"' EXIT
  trap 'exit 130' INT TERM
  local t0=$SECONDS
  echo "debian-root $NAME: debootstrap $SUITE into $tmp from $(mirror)"
  debootstrap --variant=minbase "$SUITE" "$tmp" "$(mirror)" >"$tmp.log" 2>&1 ||
    { tail -20 "$tmp.log" >&2; die "debootstrap failed (log above)"; }
  echo "debian-root $NAME: installing ${PACKAGES[*]} in the root"
  install_in "$tmp" "$tmp.log" "${PACKAGES[@]}"
  local ver
  ver=$(root_check "$tmp")
  [ -n "$ver" ] || die "the new root does not work (no version from its $NAME check)"
  echo "$ver, made $(date -u +%Y-%m-%dT%H:%MZ) in $((SECONDS - t0)) s" >"$tmp/.libblend-root-ok"
  rm -rf "$ROOT"
  mv "$tmp" "$ROOT"
  rm -f "$tmp.log"
  trap - EXIT
  echo "debian-root $NAME: made $ROOT ($(cat "$MARK"))"
}

# run_in ROOTDIR DIR... -- CMD...
run_in() {
  local r=$1
  shift
  local binds=()
  while [ $# -gt 0 ] && [ "$1" != "--" ]; do
    binds+=("$(cd "$1" && pwd)")
    shift
  done
  [ "${1:-}" = "--" ] || die "usage: debian-root.sh $NAME run DIR... -- CMD..."
  shift
  [ $# -gt 0 ] || die "usage: debian-root.sh $NAME run DIR... -- CMD..."
  exec unshare --mount --propagation private bash -c '
    set -e
    r=$1; n=$2; shift 2
    mount -t proc proc "$r/proc"
    mount --rbind /dev "$r/dev"
    for ((i = 0; i < n; i++)); do
      mkdir -p "$r$1"
      mount --bind "$1" "$r$1"
      shift
    done
    cwd=$(pwd)
    [ -d "$r$cwd" ] || cwd=/
    exec chroot "$r" env -C "$cwd" HOME=/root LANG=C.UTF-8 "$@"
  ' _ "$r" "${#binds[@]}" "${binds[@]}" "$@"
}

case "${1:-}" in
ensure) ensure ;;
path) echo "$ROOT" ;;
run)
  shift
  [ -f "$MARK" ] || die "no root at $ROOT: run 'scripts/debian-root.sh $NAME ensure' first"
  run_in "$ROOT" "$@"
  ;;
*)
  echo "usage: debian-root.sh $NAME ensure | path | run DIR... -- CMD..." >&2
  exit 2
  ;;
esac
