#!/usr/bin/env bash
# Labels recordings whose words are known with the project's own forced aligner (`lipsync align`),
# for training templates (`lipsync train`) and for evaluation: the aligner as the labeller.
#
#   scripts/label-with-aligner.sh IN_DIR OUT_DIR [--voice VOICE | --voice SPEAKER=VOICE ...]
#                                 [--templates FILE] [--min-word-confidence X]
#
# IN_DIR holds NAME.wav with NAME.txt (the words) beside it, directly or in one folder per
# speaker (IN_DIR/SPEAKER/), as scripts/fetch-real-speech.sh makes them. Every file is aligned
# on its words and OUT_DIR/[SPEAKER/]NAME.wav (a link to the recording) + NAME.lab (common-set
# labels) are written. Only confident labels are kept: a file where the aligner fell back to
# audio-only analysis, or left any word unplaced, is skipped and counted. The voice is en-us
# unless given (per speaker: --voice asterisk-it-carlo=it). Reproducible: the same build,
# templates and espeak-ng give the same labels.
# Exit codes: 0 done, 1 error (lipsync failed on a file), 2 usage.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
lipsync="${LIPSYNC:-$here/build/cli/lipsync}"
usage() { echo "usage: label-with-aligner.sh IN_DIR OUT_DIR [--voice [SPEAKER=]VOICE ...] [--templates FILE] [--min-word-confidence X]" >&2; exit 2; }
[ $# -ge 2 ] || usage
in="$1" out="$2"
shift 2
[ -d "$in" ] || { echo "label-with-aligner.sh: $in: not a folder" >&2; exit 2; }
voices=() extra=()
while [ $# -gt 0 ]; do
  case "$1" in
    --voice) [ $# -ge 2 ] || usage; voices+=("$2"); shift 2 ;;
    --templates|--min-word-confidence) [ $# -ge 2 ] || usage; extra+=("$1" "$2"); shift 2 ;;
    *) usage ;;
  esac
done
[ -x "$lipsync" ] || { echo "label-with-aligner.sh: $lipsync not built (cmake --build build --target lipsync)" >&2; exit 1; }

voice_for() {  # the voice of a speaker: SPEAKER=VOICE, else a bare VOICE, else en-us
  local speaker="$1" voice=en-us v
  for v in "${voices[@]+"${voices[@]}"}"; do
    case "$v" in
      "$speaker"=*) echo "${v#*=}"; return ;;
      *=*) ;;
      *) voice="$v" ;;
    esac
  done
  echo "$voice"
}

label_folder() {  # label_folder SRC DST SPEAKER
  local src="$1" dst="$2" speaker="$3" made=0 skipped=0 wav name words voice
  voice="$(voice_for "$speaker")"
  shopt -s nullglob
  for wav in "$src"/*.wav; do
    name="$(basename "$wav" .wav)"
    [ -f "$src/$name.txt" ] || continue
    mkdir -p "$dst"
    words="$(mktemp)"
    if ! "$lipsync" align "$wav" --text-file "$src/$name.txt" --voice "$voice" -q \
        -s "$dst/$name.lab.tmp" --words "$words" "${extra[@]+"${extra[@]}"}" 2>"$words.err"; then
      echo "label-with-aligner.sh: $wav: lipsync align failed: $(cat "$words.err")" >&2
      rm -f "$words" "$words.err" "$dst/$name.lab.tmp"
      exit 1
    fi
    # Confident only: no fallback to audio-only analysis, every word placed.
    if grep -q "audio-only analysis used for the whole file" "$words.err" ||
       awk -F'\t' '!/^#/ && $5 != "yes" { bad = 1 } END { exit !bad }' "$words"; then
      rm -f "$dst/$name.lab.tmp"
      skipped=$((skipped + 1))
    else
      mv "$dst/$name.lab.tmp" "$dst/$name.lab"
      ln -sfn "$(cd "$src" && pwd)/$name.wav" "$dst/$name.wav"
      made=$((made + 1))
    fi
    rm -f "$words" "$words.err"
  done
  [ $((made + skipped)) -eq 0 ] ||
    echo "label-with-aligner.sh: ${speaker}: $made files labelled ($skipped skipped: a word not placed or no alignment)" >&2
}

label_folder "$in" "$out" "$(basename "$(cd "$in" && pwd)")"
for sub in "$in"/*/; do
  [ -d "$sub" ] || continue
  speaker="$(basename "$sub")"
  label_folder "${sub%/}" "$out/$speaker" "$speaker"
done
