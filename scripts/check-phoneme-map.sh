#!/usr/bin/env bash
# Checks a language's phoneme map (config/phonemes/espeak-LANG.toml) the way the shipped ones were
# checked (docs/measurements.md, "Languages from espeak-ng's IPA"): tuxpaint's stamp descriptions
# in that language (package tuxpaint-stamps-default, fetched into the real-speech cache), each
# said by espeak-ng with `lipsync say --voice VOICE`, then aligned back with `lipsync eval
# --align`, espeak-ng's own phoneme times as truth. Prints how many lines were said with a
# warning (and the commonest warnings), the aligned visual groups and boundary errors, and the
# visual groups from the audio alone. A new language is ready when few lines warn and it aligns
# about as well as the others (84-91 % visual groups, median boundary error under 10 ms).
#
#   scripts/check-phoneme-map.sh VOICE [TUXPAINT_LANG] [LINES]
#
# TUXPAINT_LANG is the language's name in tuxpaint's NAME.txt files (default: VOICE; pt_BR for
# pt-br), LINES how many descriptions, first by sort order (default 120). With CHECK_MIN_GROUPS
# (percent) or CHECK_MAX_WARNED (lines) set, falling short of either fails.
# Exit codes: 0 done (and within those), 1 error or short of them, 2 usage, 77 the package
# cannot be fetched.
set -euo pipefail
[ $# -ge 1 ] && [ $# -le 3 ] && [ "${1#-}" = "$1" ] || {
  sed -n '2,/^[^#]/s/^# \{0,1\}//p' "$0" >&2
  exit 2
}
voice="$1" tuxlang="${2:-$1}" lines="${3:-120}"
here="$(cd "$(dirname "$0")/.." && pwd)"
lipsync="${LIPSYNC:-$here/build/cli/lipsync}"
cache="${REAL_SPEECH_CACHE:-$here/build/real-speech-cache}"
corpus="${CHECK_DIR:-$here/build/phoneme-map-check}/$voice"  # one speaker: the voice
work="$corpus/$voice"
[ -x "$lipsync" ] || { echo "check-phoneme-map.sh: $lipsync not built (scripts/build.sh)" >&2; exit 1; }

package=tuxpaint-stamps-default
"$here/scripts/fetch-packages.sh" "$cache" "$package"

rm -rf "$corpus" && mkdir -p "$work"
find "$cache/root/usr/share/tuxpaint/stamps" -name '*.txt' -print0 |
  xargs -0 grep -h "^$tuxlang.utf8=" | cut -d= -f2- | sed 's/^ *//' | grep . | sort -u |
  head -n "$lines" >"$work/lines" || true
total=$(wc -l <"$work/lines")
[ "$total" -gt 0 ] || { echo "check-phoneme-map.sh: no '$tuxlang.utf8=' lines in $package" >&2; exit 1; }

n=0 warned=0
while IFS= read -r line; do
  n=$((n + 1))
  f="$(printf '%s/%04d' "$work" "$n")"
  printf '%s\n' "$line" >"$f.txt"
  if ! "$lipsync" say --voice "$voice" "$line" --wav "$f.wav" --schedule "$f.lab" 2>"$f.err" \
      >/dev/null; then
    cat "$f.err" >&2  # no map for the language, an unknown voice: every line would fail alike
    exit 1
  fi
  [ -s "$f.err" ] && warned=$((warned + 1))
done <"$work/lines"
echo "check-phoneme-map.sh: $voice: $n lines said, $warned with a warning"
cat "$work"/*.err | sort | uniq -c | sort -rn | head -5
rm -f "$work"/*.err "$work/lines"

eval_row() {  # the speaker's row of the table whose header starts with $1
  awk -v head="$1" -v who="$voice" '$1 == "speaker" && $2 == head {on = 1; next}
                                     on && $1 == who {print; exit}'
}
aligned=$("$lipsync" eval --corpus "$corpus" --align --voice "$voice=$voice" --no-per-file 2>/dev/null)
audio=$("$lipsync" eval --corpus "$corpus" --no-per-file 2>/dev/null)
read -r _ _ _ group _ <<<"$(eval_row frames <<<"$aligned")"
read -r _ _ median _ within20 within50 _ <<<"$(eval_row boundaries <<<"$aligned")"
read -r _ _ _ audiogroup _ <<<"$(eval_row frames <<<"$audio")"
echo "check-phoneme-map.sh: $voice: aligned back $group visual groups, boundaries median" \
  "$median ms, $within50 within 50 ms; from the audio alone $audiogroup"
short=0
if [ -n "${CHECK_MAX_WARNED:-}" ] && [ "$warned" -gt "$CHECK_MAX_WARNED" ]; then
  echo "check-phoneme-map.sh: $voice: $warned lines warned, more than $CHECK_MAX_WARNED" >&2
  short=1
fi
if [ -n "${CHECK_MIN_GROUPS:-}" ] &&
    ! awk -v g="${group%\%}" -v m="$CHECK_MIN_GROUPS" 'BEGIN {exit !(g + 0 >= m + 0)}'; then
  echo "check-phoneme-map.sh: $voice: aligned back $group, under $CHECK_MIN_GROUPS %" >&2
  short=1
fi
exit "$short"
