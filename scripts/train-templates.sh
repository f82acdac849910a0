#!/usr/bin/env bash
# Regenerates the shipped default templates, config/templates/default.json, from espeak-ng speech
# only (scripts/make-corpus.sh train: 40 sentences x 12 voices and variants). Reproducible: the
# same espeak-ng and the same build give the same file. The development corpus (held-out
# sentences and voices) is never used here; it is for `lipsync eval`.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
lipsync="${LIPSYNC:-$here/build/cli/lipsync}"
corpus="${CORPUS_DIR:-$here/build/corpus/train}"
"$here/scripts/make-corpus.sh" train "$corpus"
"$lipsync" train "$corpus" -o "$here/config/templates/default.json" \
  --description "Default templates: trained by scripts/train-templates.sh on espeak-ng $(espeak-ng --version | awk '{print $4}') speech (12 voices and variants, 40 sentences)"
