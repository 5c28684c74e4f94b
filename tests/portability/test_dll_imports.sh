#!/usr/bin/env bash
# libblend.dll (the mingw-w64 build) is self-contained: it imports only
# Windows' own DLLs (no libwinpthread-1.dll, libgcc_s or JSON DLL to ship
# beside it), and it exports exactly the public API: every LB_API function
# of the headers and nothing else.
#   test_dll_imports.sh libblend.dll INCLUDE_DIR
set -euo pipefail
dll=$1 inc=$2
objdump=x86_64-w64-mingw32-objdump
imports=$("$objdump" -p "$dll" | awk '/DLL Name:/ {print $3}')
bad=$(echo "$imports" | grep -viE '^(kernel32|msvcrt|ucrtbase|user32|advapi32|ws2_32|bcrypt|ntdll|api-ms-win-[a-z0-9-]+)\.dll$' || true)
if [ -n "$bad" ]; then
  echo "test_dll_imports: $dll imports DLLs that Windows does not have: $(echo "$bad" | tr '\n' ' ')" >&2
  exit 1
fi
exports=$("$objdump" -p "$dll" | awk '/\[Ordinal\/Name Pointer\] Table/ {on = 1; next} on && /^\t\[/ {print $NF} on && /^$/ {on = 0}' | sort)
api=$(grep -h '^LB_API' "$inc"/*.h | sed -E 's/\(.*//; s/.*[ *]//' | sort)
if [ "$exports" != "$api" ]; then
  echo "test_dll_imports: $dll exports differ from the headers' LB_API functions:" >&2
  diff <(echo "$api") <(echo "$exports") >&2 || true
  exit 1
fi
echo "test_dll_imports: imports $(echo "$imports" | tr '\n' ' ')and exports the $(echo "$exports" | wc -l) API functions"
