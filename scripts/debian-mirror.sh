#!/usr/bin/env bash
# Prints the Debian mirror this machine already uses (deb822 or one-line
# sources; http://deb.debian.org/debian when neither names one). Shared by
# scripts/debian-root.sh (debootstrap) and scripts/third-party.sh (source
# packages).
set -euo pipefail
m=""
if [ -f /etc/apt/sources.list.d/debian.sources ]; then
  m=$(awk '/^URIs:/ {print $2; exit}' /etc/apt/sources.list.d/debian.sources)
fi
if [ -z "$m" ] && [ -f /etc/apt/sources.list ]; then
  m=$(awk '$1 == "deb" && $0 !~ /security/ {for (i = 2; i <= NF; i++) if ($i ~ /^https?:/) {print $i; exit}}' /etc/apt/sources.list)
fi
echo "${m:-http://deb.debian.org/debian}"
