#!/usr/bin/env bash
# Generates a labelled speech corpus with espeak-ng: for every sentence and voice,
# VOICE/sNN.wav and VOICE/sNN.lab (common-set labels from espeak-ng's own phoneme events, so they
# are exact; sNN is the NNth sentence of the list). One folder per voice: `lipsync eval` gives
# figures per speaker, and the worst one is the figure that counts.
#
#   scripts/make-corpus.sh train OUT_DIR   # the training corpus (templates are trained on it)
#   scripts/make-corpus.sh dev OUT_DIR     # the development corpus (held-out sentences AND voices)
#
# Needs the built tool (build/cli/lipsync, or $LIPSYNC). Reproducible: same espeak-ng, same files.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
lipsync="${LIPSYNC:-$here/build/cli/lipsync}"
kind="${1:?usage: make-corpus.sh train|dev OUT_DIR}"
out="${2:?usage: make-corpus.sh train|dev OUT_DIR}"

case "$kind" in
  # Voices and variants: accents, sexes, ages and the klatt formant synthesiser, each at its own
  # rate and pitch, so the templates see speaker variety rather than one voice.
  train)
    sentences="$here/config/corpus/train-sentences.txt"
    voices=("en-us:175:50" "en-gb:160:45" "en-us+f2:170:60" "en-us+m3:185:40" "en-gb+f4:150:70"
            "en-us+klatt:175:50" "en-gb-x-rp+m1:165:35" "en-gb-scotland:170:50" "en-us+f1:190:65"
            "en-029+m2:160:45" "en-us+klatt2:150:55" "en-gb-x-gbcwmd+f3:175:60") ;;
  dev)
    sentences="$here/config/corpus/dev-sentences.txt"
    voices=("en-us+f5:165:55" "en-gb-x-rp+m7:180:40" "en-us+klatt4:170:50" "en-gb-x-gbclan:160:45"
            "en-us+m6:175:35" "en-gb+f2:185:65") ;;
  *) echo "make-corpus.sh: first argument must be train or dev" >&2; exit 2 ;;
esac
[ -x "$lipsync" ] || { echo "make-corpus.sh: $lipsync not built (run scripts/build.sh)" >&2; exit 1; }

mkdir -p "$out"
n=0
while IFS= read -r line; do
  case "$line" in ''|'#'*) continue ;; esac
  n=$((n + 1))
  for v in "${voices[@]}"; do
    IFS=: read -r voice rate pitch <<<"$v"
    dir="$out/${voice//+/_}"
    name="$(printf 's%02d' "$n")"
    [ -s "$dir/$name.lab" ] && continue
    mkdir -p "$dir"
    "$lipsync" say "$line" --voice "$voice" --rate "$rate" --pitch "$pitch" \
      --wav "$dir/$name.wav" --schedule "$dir/$name.lab" 2>>"$out/warnings.txt"
  done
done <"$sentences"
echo "make-corpus.sh: $kind corpus in $out ($(ls "$out"/*/*.wav | wc -l) files)" >&2
