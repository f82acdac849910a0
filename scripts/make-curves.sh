#!/usr/bin/env bash
# Regenerates the shipped English curve set from its rules (on purpose only: a test checks the
# committed file is what the rules give).
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
lipsync="${LIPSYNC:-$here/build/cli/lipsync}"
"$lipsync" curves generate --rules "$here/config/curves/english-rules.toml" -o "$here/config/curves/english.json"
