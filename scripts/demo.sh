#!/usr/bin/env bash
# The main job on the bundled example: installs what is missing, builds, then turns the
# example speech (config/examples/hello.wav, made by espeak-ng) into a phoneme schedule and
# scores it against espeak-ng's own timings. Results land in ./out/.
set -euo pipefail
cd "$(dirname "$0")/.."
"./scripts/build.sh"
lipsync=./build/cli/lipsync
example=config/examples/hello.wav
mkdir -p out

echo "== lipsync analyze $example  (audio -> phoneme schedule)"
"$lipsync" analyze "$example" --schedule out/hello.tsv --frames out/hello-frames.csv
echo "   first segments of out/hello.tsv (start, end, phoneme, confidence):"
head -n 8 out/hello.tsv | sed 's/^/     /'

echo "== lipsync eval --corpus config/examples  (schedule vs espeak-ng's own timings)"
"$lipsync" eval --corpus config/examples | tail -n 1
