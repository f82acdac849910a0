#!/usr/bin/env bash
# Replays a small subset of the real dev speakers (config/corpus/real-speakers.txt) through
# `lipsync eval`, one run per speaker, each against its own floor (visual-group accuracy).
#
#   real-dev-replay.sh LIPSYNC OUT_DIR SUBSET SPEAKER=FLOOR...
#
# Exits 77 (ctest: skipped) only when scripts/fetch-real-speech.sh cannot fetch the packages
# or tools; any other failure fails the test.
set -uo pipefail
here="$(cd "$(dirname "$0")/../.." && pwd)"
lipsync="$1" out="$2" subset="$3"
shift 3
"$here/scripts/fetch-real-speech.sh" "$out" --split dev --subset "$subset"
rc=$?
if [ "$rc" -eq 77 ]; then
  echo "real-dev-replay: SKIPPED: the real-speech packages or tools cannot be fetched (see above)"
  exit 77
fi
[ "$rc" -eq 0 ] || exit "$rc"
failed=0
for pair in "$@"; do
  speaker="${pair%%=*}" floor="${pair#*=}"
  echo "== $speaker (floor: visual groups $floor)"
  "$lipsync" eval --corpus "$out/dev/$speaker" --no-per-file --min-group-accuracy "$floor" |
    tail -2 || failed=1
done
exit "$failed"
