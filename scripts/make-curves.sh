#!/usr/bin/env bash
# Regenerates the shipped curve sets from their rules (on purpose only: a test checks the
# committed files are what the rules give): English, and the Mandarin additions on top of it.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
lipsync="${LIPSYNC:-$here/build/cli/lipsync}"
"$lipsync" curves generate --rules "$here/config/curves/english-rules.toml" -o "$here/config/curves/english.json"
"$lipsync" curves generate --rules "$here/config/curves/mandarin-rules.toml" --phonemes mandarin \
  --additions-for yu --base english -o "$here/config/curves/mandarin.json"
