#!/usr/bin/env bash
# How a change to the front end or its training is judged before it ships: on voices the
# templates have never heard, never on the dev speakers (docs/measurements.md, "Real people").
#
#   scripts/held-out-check.sh [--work DIR] [--no-fetch] [--dev]
#
# Make the change first (code: rebuild, or point $LIPSYNC at another build; training data or
# recipe: config/corpus/real-speakers.txt, scripts/train-templates.sh), then run this. It
#  1. trains the shipped recipe (scripts/train-templates.sh) three times: without klettres-en-gb,
#     without asterisk-en-allison, and with every training speaker (into --work, default
#     build/held-out-check; config/templates is not touched);
#  2. scores each of those two speakers on the set trained without it, from the audio alone and
#     aligned on its words; the voices held out for decisions (config/corpus/real-speakers.txt,
#     split tune) on the full set, the same two ways; and espeak-ng's dev corpus (held-out voices
#     and sentences) on the full set, all voices and the worst;
#  3. with --dev, also the dev speakers on the full set: the figures the README reports, for the
#     record once a change is chosen, never to choose it.
# One line a speaker: visual groups, jaw r through the jaw-servo puppet, bilabial closures caught
# and false closures. Retraining alone moves a tune voice by up to about a point and a half:
# compare two runs of this script, not one run with the shipped set's figures.
#
# Needs the real speech (scripts/fetch-real-speech.sh; fetched and labelled here, some minutes,
# unless --no-fetch finds it in $REAL_SPEECH_DIR, default build/real-speech) and python3.
# Exit codes: 0 done, 1 error, 2 usage.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
lipsync="${LIPSYNC:-$here/build/cli/lipsync}"
real="${REAL_SPEECH_DIR:-$here/build/real-speech}"
espeak_dev="${CORPUS_DEV_DIR:-$here/build/corpus/dev}"
usage() {
  echo "usage: scripts/held-out-check.sh [--work DIR] [--no-fetch] [--dev]" >&2
  exit 2
}
work="$here/build/held-out-check" fetch=1 dev=0
while [ $# -gt 0 ]; do
  case "$1" in
    --work) [ $# -ge 2 ] || usage; work="$2"; shift ;;
    --no-fetch) fetch=0 ;;
    --dev) dev=1 ;;
    -h|--help) sed -n '2,/^[^#]/s/^# \{0,1\}//p' "$0"; exit 0 ;;
    *) usage ;;
  esac
  shift
done
[ -x "$lipsync" ] || { echo "held-out-check.sh: $lipsync not built (run scripts/build.sh)" >&2; exit 1; }
left_out=(klettres-en-gb asterisk-en-allison)

if [ "$fetch" = 1 ]; then
  for split in train networks tune $([ "$dev" = 1 ] && echo dev); do
    "$here/scripts/fetch-real-speech.sh" "$real" --split "$split" ||
      { echo "held-out-check.sh: fetching the $split speakers failed" >&2; exit 1; }
  done
fi
for dir in "$real/tune" $([ "$dev" = 1 ] && echo "$real/dev"); do
  [ -d "$dir" ] || { echo "held-out-check.sh: $dir missing: run without --no-fetch" >&2; exit 1; }
done
"$here/scripts/make-corpus.sh" dev "$espeak_dev"

mkdir -p "$work"
train() {
  echo "held-out-check.sh: training $1" >&2
  REAL_SPEECH_DIR="$real" LIPSYNC="$lipsync" "$here/scripts/train-templates.sh" --no-fetch \
    "${@:2}" -o "$work/$1.json" >"$work/$1.log" 2>&1 ||
    { echo "held-out-check.sh: training $1 failed: $work/$1.log" >&2; exit 1; }
}
for speaker in "${left_out[@]}"; do train "without-$speaker" --leave-out "$speaker"; done
train all

# The espeak-ng voice reading each real speaker's words (the language in its SOURCE column).
voices=()
while read -r speaker split source; do
  case "$speaker" in ''|'#'*) continue ;; esac
  case "$source" in
    asterisk:*) lang="${source##*:}" ;;
    fillets:*) lang="${source#fillets:}" lang="${lang%%:*}" ;;
    festvox-ru) lang=ru ;;
    *) lang=en ;;
  esac
  [ "$lang" = en ] || voices+=(--voice "$speaker=$lang")
done <"$here/config/corpus/real-speakers.txt"

# eval NAME CORPUS TEMPLATES [OPTIONS]: the figures as JSON in $work/NAME.json.
score() {
  echo "held-out-check.sh: scoring $1" >&2
  "$lipsync" eval --corpus "$2" --templates "$3" --no-per-file --json "$work/$1.json" "${@:4}" \
    >/dev/null 2>"$work/$1.log" ||
    { echo "held-out-check.sh: scoring $1 failed: $work/$1.log" >&2; exit 1; }
}
for speaker in "${left_out[@]}"; do
  mkdir -p "$work/corpus-$speaker"
  ln -sfn "$real/train/$speaker" "$work/corpus-$speaker/$speaker"
  score "$speaker-audio" "$work/corpus-$speaker" "$work/without-$speaker.json"
  score "$speaker-aligned" "$work/corpus-$speaker" "$work/without-$speaker.json" --align
done
score tune-audio "$real/tune" "$work/all.json"
score tune-aligned "$real/tune" "$work/all.json" --align "${voices[@]}"
score espeak-dev "$espeak_dev" "$work/all.json"
if [ "$dev" = 1 ]; then
  score dev-audio "$real/dev" "$work/all.json"
  score dev-aligned "$real/dev" "$work/all.json" --align "${voices[@]}"
fi

python3 - "$work" "$dev" "${left_out[@]}" <<'EOF'
import json, sys
from pathlib import Path

work, dev, left_out = Path(sys.argv[1]), sys.argv[2] == "1", sys.argv[3:]

def rows(name):
    return json.loads((work / f"{name}.json").read_text())["speakers"]

def line(speaker, figures):
    jaw = figures["jaw"]["audio"]
    closures = f"{100 * jaw['closures_caught']:5.1f} %" if jaw["closures"] else "    -  "
    return (f"  {speaker:30} {100 * figures['group_accuracy']:5.1f} %   {jaw['r']:5.2f}   "
            f"{closures}   {100 * jaw['false_closures']:5.1f} %")

def table(title, runs):
    """runs: (file name, how) pairs; every speaker of each file, `how` after its name."""
    print(f"{title}\n  {'speaker':30} groups   jaw r   closures   false")
    for name, how in runs:
        for speaker, figures in sorted(rows(name).items()):
            print(line(f"{speaker}, {how}", figures))

table("Training speakers, each left out of its own set",
      [(f"{s}-{how}", how) for s in left_out for how in ("audio", "aligned")])
table("Voices held out for decisions (split tune), full set",
      [("tune-audio", "audio"), ("tune-aligned", "aligned")])
espeak = rows("espeak-dev")
worst = min(espeak, key=lambda s: espeak[s]["group_accuracy"])
total = json.loads((work / "espeak-dev.json").read_text())
print(f"espeak-ng dev, full set: {100 * total['group_accuracy']:.1f} % visual groups, worst voice "
      f"{worst} {100 * espeak[worst]['group_accuracy']:.1f} %")
if dev:
    table("Dev speakers, full set (the reported figures: not for choosing)",
          [("dev-audio", "audio"), ("dev-aligned", "aligned")])
EOF
