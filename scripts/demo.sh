#!/usr/bin/env bash
# The main job on the bundled example: installs what is missing, builds, then takes the example
# speech (config/examples/hello.wav, made by espeak-ng) through the whole chain: audio → phoneme
# schedule (scored against espeak-ng's own timings) → mouth-pose weights → a chart → the
# lipsyncd service playing it with a virtual puppet moving in the terminal, in sync with the
# sound. Results land in ./out/.
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

echo "== 2. lipsync eval --corpus config/examples  (schedule and the jaw-servo puppet's jaw vs espeak-ng's own timings)"
"$lipsync" eval --corpus config/examples | tail -n 2

echo "== 3. lipsync plot  (pose curves with the phonemes under them)"
"$lipsync" plot --weights out/hello.csv --schedule out/hello.tsv -o out/hello.svg
echo "   wrote out/hello.svg"

echo "== 4. lipsyncd, the service: plays the example and says a line, the terminal puppet in sync"
# Sound to the default ALSA device where there is a sound card, else to the null device (a
# real-time clock with no sound). The service runs in the foreground here; under systemd it is
# systemd/lipsyncd.service.
device=null
if [ -e /proc/asound/cards ] && grep -q '^ *[0-9]' /proc/asound/cards 2>/dev/null; then device=default; fi
cat >out/lipsyncd.toml <<TOML
[audio]
device = "$device"
[mouth]
puppet = "terminal"
hardware = false
terminal = true
record = "$PWD/out/hello-commands.csv"
[control]
socket = "$PWD/out/control.sock"
TOML
./build/daemon/lipsyncd --config out/lipsyncd.toml &
daemon=$!
trap 'kill $daemon 2>/dev/null || true' EXIT
for _ in $(seq 50); do [ -S out/control.sock ] && break; sleep 0.1; done
"$lipsync" ctl --socket out/control.sock play "$example" >/dev/null
"$lipsync" ctl --socket out/control.sock say "And that is how a puppet talks." >/dev/null
"$lipsync" ctl --socket out/control.sock --wait status >/dev/null
kill -TERM $daemon; wait $daemon || true
trap - EXIT
echo "== done (audio: $device): out/hello.tsv, out/hello.csv, out/hello.svg, out/hello-commands.csv"
