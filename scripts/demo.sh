#!/usr/bin/env bash
# The main job on the bundled example: installs what is missing, builds, then takes the example
# speech (config/examples/hello.wav, made by espeak-ng) through the whole chain: audio → phoneme
# schedule (scored against espeak-ng's own timings) → mouth-pose weights → a chart → a virtual
# puppet moving in the terminal at real time. Results land in ./out/.
set -euo pipefail
cd "$(dirname "$0")/.."
"./scripts/build.sh"
lipsync=./build/cli/lipsync
example=config/examples/hello.wav
mkdir -p out

echo "== 1. lipsync analyze $example  (audio -> phoneme schedule -> pose weights)"
"$lipsync" analyze "$example" --schedule out/hello.tsv --frames out/hello-frames.csv --weights out/hello.csv
echo "   first segments of out/hello.tsv (start, end, phoneme, confidence):"
head -n 6 out/hello.tsv | sed 's/^/     /'

echo "== 2. lipsync eval --corpus config/examples  (schedule vs espeak-ng's own timings)"
"$lipsync" eval --corpus config/examples | tail -n 1

echo "== 3. lipsync plot  (pose curves with the phonemes under them)"
"$lipsync" plot --weights out/hello.csv --schedule out/hello.tsv -o out/hello.svg
echo "   wrote out/hello.svg"

echo "== 4. lipsync drive --puppet terminal --realtime  (the puppet, as bars; ends at rest)"
"$lipsync" drive --weights out/hello.csv --puppet terminal --no-hardware --realtime --terminal \
  --record out/hello-commands.csv
echo "== done: out/hello.tsv, out/hello.csv, out/hello.svg, out/hello-commands.csv"
