#!/usr/bin/env bash
# Runs a Windows program under Wine (Debian's wine64), in libblend's own Wine
# prefix: $LIBBLEND_WINEPREFIX, default ~/.cache/libblend/wine (made on the
# first run, about 10 s; later starts take under a second). ctest uses this
# as the cross-compiling emulator of the Windows build
# (cmake/mingw-w64-x86_64.cmake).
#   wine-run.sh PROGRAM.exe ARGS...
#   wine-run.sh --hold      start the prefix's wineserver for good (until --release)
#   wine-run.sh --release   stop it
# Why hold: a wineserver started by a program exits 3 s after its last
# client, and a program that connects while it is exiting dies with "wine
# client error:0: recvmsg: Connection reset by peer" (it failed a CI run,
# ctest starting tests 2 at a time). A server held for the whole test stage
# never exits under a program, and --hold starts Wine's services itself.
set -euo pipefail
WINE=${LIBBLEND_WINE:-/usr/lib/wine/wine64}
[ -x "$WINE" ] || {
  echo "wine-run: $WINE is missing: install Debian's wine64 (scripts/install-deps.sh does)" >&2
  exit 127
}
export WINEPREFIX=${LIBBLEND_WINEPREFIX:-${XDG_CACHE_HOME:-$HOME/.cache}/libblend/wine}
export WINEDEBUG=${WINEDEBUG:--all} WINEDLLOVERRIDES=${WINEDLLOVERRIDES:-"mscoree,mshtml="}
if [ ! -f "$WINEPREFIX/.libblend-ok" ]; then
  # the first start makes the prefix: one process at a time (ctest runs
  # tests in parallel)
  mkdir -p "$(dirname "$WINEPREFIX")"
  exec 9>"$WINEPREFIX.lock"
  flock 9
  if [ ! -f "$WINEPREFIX/.libblend-ok" ]; then
    "$WINE" cmd /c exit >/dev/null 2>&1 || true
    "$(dirname "$WINE")/wineserver" -w 2>/dev/null || true
    [ -f "$WINEPREFIX/system.reg" ] || {
      echo "wine-run: could not make the Wine prefix $WINEPREFIX" >&2
      exit 1
    }
    touch "$WINEPREFIX/.libblend-ok"
  fi
  flock -u 9
  exec 9>&-
fi
WINESERVER="$(dirname "$WINE")/wineserver"
case "${1-}" in
--hold)
  # exit status 2: a server already runs for this prefix (held or not)
  "$WINESERVER" -p </dev/null >/dev/null 2>&1 || [ $? -eq 2 ]
  # Wine's own services (services.exe, winedevice.exe, ...) live as long as a
  # held server; started here, they hold no test's output pipe open (ctest
  # waits for a test's pipe to close)
  "$WINE" cmd /c exit </dev/null >/dev/null 2>&1 || true
  exit 0
  ;;
--release)
  "$WINESERVER" -k 2>/dev/null || true
  exit 0
  ;;
esac
exec "$WINE" "$@"
