#!/usr/bin/env bash
# Regenerates the fuzz seed corpus (fuzz/seeds) from espeak-ng speech: small files of each kind
# the decoder meets, valid and broken. Needs the built tool and sox. Run on purpose only.
# Seed layout: first byte 0x00 = "a file", 0x01 + format,channels,rate bytes = raw PCM.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
lipsync="${LIPSYNC:-$here/build/cli/lipsync}"
out="$here/fuzz/seeds"
tmp="$(mktemp -d)"; trap 'rm -rf "$tmp"' EXIT
"$lipsync" say "ah, map" --voice en-us --rate 250 --wav "$tmp/speech.wav"
sox "$tmp/speech.wav" -r 8000 "$tmp/s16.wav" trim 0 0.25
sox "$tmp/s16.wav" -e floating-point -b 32 "$tmp/float.wav"
sox "$tmp/s16.wav" -b 24 -c 2 "$tmp/stereo24.wav"
sox "$tmp/s16.wav" "$tmp/speech.flac"
sox "$tmp/s16.wav" "$tmp/speech.ogg"
sox "$tmp/s16.wav" -t raw -e signed -b 16 "$tmp/s16.raw"
rm -f "$out"/*; mkdir -p "$out"
for f in s16.wav float.wav stereo24.wav speech.flac speech.ogg; do
  { printf '\x00'; cat "$tmp/$f"; } >"$out/$f"
done
{ printf '\x00'; head -c 60 "$tmp/s16.wav"; } >"$out/truncated-header.wav"
{ printf '\x00'; head -c 2000 "$tmp/s16.wav"; } >"$out/truncated-data.wav"
{ printf '\x00'; head -c 44 "$tmp/s16.wav"; } >"$out/zero-length.wav"
{ printf '\x00'; echo "not audio at all"; } >"$out/text.txt"
# raw: s16 (index 2), 1 channel (0), 8000 Hz (index 0)
{ printf '\x01\x02\x00\x00'; cat "$tmp/s16.raw"; } >"$out/raw-s16-8k.raw"
# raw f32 (index 5), 2 channels (1), 48 kHz (index 5): NaN and infinity patterns
{ printf '\x01\x05\x01\x05'; for i in $(seq 64); do printf '\x00\x00\xc0\x7f\x00\x00\x80\x7f'; done; } >"$out/raw-nan.raw"
ls -l "$out"
