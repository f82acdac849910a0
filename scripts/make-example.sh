#!/usr/bin/env bash
# Regenerates the bundled example (config/examples/hello.wav + hello.lab): a puppet's line
# spoken by espeak-ng, with espeak-ng's own phoneme timings as the reference labels. The voice
# is one of the held-out (dev) voices, so the demo's accuracy figure is honest.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
lipsync="${LIPSYNC:-$here/build/cli/lipsync}"
out="$here/config/examples"
mkdir -p "$out"
"$lipsync" say "Hello there! I am a puppet. Watch my mouth move when I talk, and wave back at me." \
  --voice en-us+m6 --rate 165 --pitch 45 --wav "$out/hello.wav" --schedule "$out/hello.lab"
echo "make-example.sh: wrote $out/hello.wav and hello.lab" >&2
