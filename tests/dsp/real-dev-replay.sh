#!/usr/bin/env bash
# Replays a small subset of the real dev speakers (config/corpus/real-speakers.txt) through
# `lipsync eval`, one run per speaker, each against its own floors: visual-group accuracy, the
# jaw-servo puppet's jaw r from the audio and, where given, the share of bilabial closures its
# jaw catches from the audio and a ceiling on its false closures; for every speaker the jaw from
# the exact labels must reach r 0.92 and catch 95 % of the bilabial closures.
#
#   real-dev-replay.sh LIPSYNC OUT_DIR SUBSET SPEAKER=GROUP_FLOOR:JAW_FLOOR[:CLOSURES:FALSE]...
#
# REPLAY_TEMPLATES=SET scores that template set (a name under config/templates/ or a file)
# instead of the default one. REPLAY_ALIGN=1 scores `lipsync align` on each file's words
# instead (eval --align), festvox-ru read by espeak-ng's ru voice. REPLAY_ADAPT=1 carries each
# speaker's voice from file to file (eval --adapt-speaker: what lipsyncd's adapt_speaker gives).
# REPLAY_FOLLOW=LAG (with REPLAY_ALIGN) follows each file as lipsyncd follows a live line said
# after its cue (eval --follow-lag LAG). REPLAY_CALIBRATE=N calibrates each speaker on its first N files (`lipsync calibrate` on their
# words: its templates and its vocal-tract-length warp) and scores the rest with that set.
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
align=()
[ -n "${REPLAY_ALIGN:-}" ] && align=(--align)
[ -n "${REPLAY_ADAPT:-}" ] && align+=(--adapt-speaker)
[ -n "${REPLAY_FOLLOW:-}" ] && align+=(--follow-lag "$REPLAY_FOLLOW")
[ ${#align[@]} -gt 0 ] && align+=(--voice festvox-ru-nsh=ru)
# Calibrates SPEAKER on its first REPLAY_CALIBRATE files into $out/calibrated/SPEAKER.json and
# links the rest into $out/calibrated/SPEAKER-rest/SPEAKER/.
calibrate() {
  local speaker="$1" voice=en-us dir="$out/calibrated" i=0 wav
  [ "$speaker" = festvox-ru-nsh ] && voice=ru
  rm -rf "$dir/$speaker-first" "$dir/$speaker-rest"
  mkdir -p "$dir/$speaker-first" "$dir/$speaker-rest/$speaker"
  for wav in "$out/dev/$speaker"/*.wav; do  # in name order
    local into="$dir/$speaker-rest/$speaker"
    [ "$i" -lt "$REPLAY_CALIBRATE" ] && into="$dir/$speaker-first"
    ln -s "$wav" "${wav%.wav}.txt" "${wav%.wav}.lab" "$into/"
    i=$((i + 1))
  done
  "$lipsync" calibrate "$dir/$speaker-first" --voice "$voice" -o "$dir/$speaker.json" 2>&1 |
    grep -E "warp [0-9.]+ \("
}
for pair in "$@"; do
  speaker="${pair%%=*}"
  IFS=: read -r group jaw closures falseClosures <<<"${pair#*=}"
  corpus="$out/dev/$speaker" templates="${REPLAY_TEMPLATES:-default}"
  if [ -n "${REPLAY_CALIBRATE:-}" ]; then
    calibrate "$speaker" || { failed=1; continue; }
    corpus="$out/calibrated/$speaker-rest" templates="$out/calibrated/$speaker.json"
  fi
  echo "== $speaker, templates $templates${REPLAY_ALIGN:+, aligned on its words}${REPLAY_ADAPT:+, the voice carried from file to file}${REPLAY_FOLLOW:+, followed $REPLAY_FOLLOW s behind} (floors: visual groups $group, jaw r from audio $jaw," \
    "closures caught ${closures:-0}, false closures at most ${falseClosures:-1})"
  "$lipsync" eval --corpus "$corpus" --no-per-file --templates "$templates" "${align[@]}" \
    --min-group-accuracy "$group" \
    --min-jaw-r "$jaw" --min-closures "${closures:-0}" --max-false-closures "${falseClosures:-1}" \
    --min-exact-jaw-r 0.92 --min-exact-closures 0.95 |
    tail -2 || failed=1
done
exit "$failed"
