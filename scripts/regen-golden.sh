#!/usr/bin/env bash
# Regenerates the golden pose weights (tests/golden/*.csv): a few espeak-ng utterances through
# `lipsync say --weights`. Run it only when a change to the runtime or the curves is meant to
# change the output, and say so in the commit.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
lipsync="${LIPSYNC:-$here/build/cli/lipsync}"
out="$here/tests/golden"
while IFS='|' read -r name voice text; do
  case "$name" in ''|'#'*) continue ;; esac
  "$lipsync" say "$text" --voice "$voice" --weights "$out/$name.csv"
done <"$out/utterances.txt"
echo "regen-golden.sh: wrote $(ls "$out"/*.csv | wc -l) files in $out" >&2
