#!/usr/bin/env bash
# Regenerates the shipped default templates, config/templates/default.json, from espeak-ng speech
# (scripts/make-corpus.sh train: 40 sentences x 12 voices and variants) and the real training
# speakers of config/corpus/real-speakers.txt (scripts/fetch-real-speech.sh: recordings of people
# from Debian packages, labelled by forced alignment or their own phone labels). Reproducible:
# the same espeak-ng, packages and build give the same file. Neither the espeak-ng development
# corpus (held-out sentences and voices) nor any real dev speaker is used here; they are for
# `lipsync eval`.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
lipsync="${LIPSYNC:-$here/build/cli/lipsync}"
corpus="${CORPUS_DIR:-$here/build/corpus/train}"
real="${REAL_SPEECH_DIR:-$here/build/real-speech}"
"$here/scripts/make-corpus.sh" train "$corpus"
rc=0
"$here/scripts/fetch-real-speech.sh" "$real" --split train || rc=$?
[ "$rc" -eq 0 ] || { echo "train-templates.sh: the real training speakers are needed (fetch-real-speech.sh exit $rc)" >&2; exit 1; }

folders=("$corpus")
speakers=()
while read -r speaker split _; do
  case "$speaker" in ''|'#'*) continue ;; esac
  [ "$split" = train ] || continue
  folders+=("$real/train/$speaker")
  speakers+=("$speaker")
done <"$here/config/corpus/real-speakers.txt"

# 24 cluster means per class: with real speakers in training, 16 / 20 / 24 gave 63.8 / 65.6 /
# 67.6 % on the espeak-ng dev corpus and the worst real dev speaker stayed within a point.
"$lipsync" train "${folders[@]}" --clusters 24 -o "$here/config/templates/default.json" \
  --description "Default templates: trained by scripts/train-templates.sh on espeak-ng $(espeak-ng --version | awk '{print $4}') speech (12 voices and variants, 40 sentences) and real speakers (24 clusters a class) ${speakers[*]}"
