#!/usr/bin/env bash
# Blender 4.x for the tests. Debian 12 ships only Blender 3.4; Debian 13
# (trixie) ships 4.3. This script keeps a trixie root made with debootstrap
# that has trixie's Blender in it, and runs commands inside it:
#
#   blender4-root.sh ensure            make the root if it is not there yet
#                                      (about 3 min and 1.8 GB the first time;
#                                      later runs only check it: cached)
#   blender4-root.sh path              print the root's folder
#   blender4-root.sh run DIR... -- CMD run CMD inside the root, with each DIR
#                                      of this machine bound at the same path
#
# The root lives in $LIBBLEND_BLENDER4_ROOT (default
# /var/cache/libblend/trixie-blender4). It is built in a sibling folder and
# renamed into place when complete, so an interrupted build leaves no
# half-made root behind (the next run starts over). Mounts are made in a
# private mount namespace (unshare), so they vanish with the command, even
# when it is killed. Needs root (debootstrap and chroot); the packages it
# needs on the host (debootstrap) are installed here, apt-get idempotent.
set -euo pipefail
ROOT=${LIBBLEND_BLENDER4_ROOT:-/var/cache/libblend/trixie-blender4}
SUITE=trixie
MARK="$ROOT/.libblend-root-ok"
# What the add-on tests need in the root: Blender, numpy for the add-on, and
# the run-time libraries of the blendtool built on the host (the tests call
# it from inside the root) and POV-Ray (the POV-Ray export is rendered).
PACKAGES=(blender python3-numpy libcjson1 libjansson4 libxxhash0 povray)

die() {
  echo "blender4-root: $*" >&2
  exit 1
}

# The Debian mirror this machine already uses (deb822 or one-line sources).
mirror() {
  local m=""
  if [ -f /etc/apt/sources.list.d/debian.sources ]; then
    m=$(awk '/^URIs:/ {print $2; exit}' /etc/apt/sources.list.d/debian.sources)
  fi
  if [ -z "$m" ] && [ -f /etc/apt/sources.list ]; then
    m=$(awk '$1 == "deb" && $0 !~ /security/ {for (i = 2; i <= NF; i++) if ($i ~ /^https?:/) {print $i; exit}}' /etc/apt/sources.list)
  fi
  echo "${m:-http://deb.debian.org/debian}"
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
      echo "blender4-root: adding to the cached root:" $miss
      # shellcheck disable=SC2086
      install_in "$ROOT" "$ROOT.log" $miss
      rm -f "$ROOT.log"
    fi
    echo "blender4-root: cached at $ROOT ($(cat "$MARK"))"
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
  echo "blender4-root: debootstrap $SUITE into $tmp from $(mirror)"
  debootstrap --variant=minbase "$SUITE" "$tmp" "$(mirror)" >"$tmp.log" 2>&1 ||
    { tail -20 "$tmp.log" >&2; die "debootstrap failed (log above)"; }
  echo "blender4-root: installing ${PACKAGES[*]} in the root"
  install_in "$tmp" "$tmp.log" "${PACKAGES[@]}"
  local ver
  ver=$(run_in "$tmp" -- blender -b --factory-startup --version 2>/dev/null | awk '/^Blender/ {print $2; exit}')
  [ -n "$ver" ] || die "blender in the new root does not start"
  echo "blender $ver, made $(date -u +%Y-%m-%dT%H:%MZ) in $((SECONDS - t0)) s" >"$tmp/.libblend-root-ok"
  rm -rf "$ROOT"
  mv "$tmp" "$ROOT"
  rm -f "$tmp.log"
  trap - EXIT
  echo "blender4-root: made $ROOT ($(cat "$MARK"))"
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
  [ "${1:-}" = "--" ] || die "usage: blender4-root.sh run DIR... -- CMD..."
  shift
  [ $# -gt 0 ] || die "usage: blender4-root.sh run DIR... -- CMD..."
  unshare --mount --propagation private bash -c '
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
  [ -f "$MARK" ] || die "no root at $ROOT: run 'scripts/blender4-root.sh ensure' first"
  run_in "$ROOT" "$@"
  ;;
*)
  echo "usage: blender4-root.sh ensure | path | run DIR... -- CMD..." >&2
  exit 2
  ;;
esac
