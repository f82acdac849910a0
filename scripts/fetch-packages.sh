#!/usr/bin/env bash
# Fetches Debian packages into a cache without installing them: `apt-get download` into
# CACHE/debs, unpacked with `dpkg -x` into CACHE/root (no root needed; a stamp CACHE/root/.PKG
# says it is there). For the scripts that read real speech or text from packages
# (fetch-real-speech.sh, check-phoneme-map.sh).
#
#   scripts/fetch-packages.sh CACHE PACKAGE...
#
# Exit codes: 0 done, 2 usage, 77 a package cannot be downloaded (tests skip).
set -euo pipefail
[ $# -ge 2 ] || { echo "usage: fetch-packages.sh CACHE PACKAGE..." >&2; exit 2; }
cache="$1"
shift
mkdir -p "$cache/debs" "$cache/root"
for p in "$@"; do
  [ -e "$cache/root/.$p" ] && continue
  ls "$cache/debs/${p}_"*.deb >/dev/null 2>&1 ||
    (cd "$cache/debs" && apt-get download -q "$p" >/dev/null 2>&1) || {
      echo "fetch-packages.sh: cannot download $p (apt-get download; is apt reachable and its" \
        "lists updated?)" >&2
      exit 77
    }
  dpkg -x "$cache/debs/${p}_"*.deb "$cache/root"
  touch "$cache/root/.$p"
done
