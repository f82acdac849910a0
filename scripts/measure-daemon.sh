#!/usr/bin/env bash
# Measures the running daemon: CPU and memory while it plays the bundled example ten times (null
# audio device, terminal puppet, no hardware), then idle, then live (the bundled example as the
# microphone). Prints one line per phase, and the status (latency) while playing.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
tmp="$(mktemp -d)"; trap 'kill $pid 2>/dev/null || true; rm -rf "$tmp"' EXIT
cat >"$tmp/lipsyncd.toml" <<TOML
[audio]
device = "null"
[mouth]
puppet = "terminal"
hardware = false
[control]
socket = "$tmp/control.sock"
[limits]
max_queue = 16
[live]
device = "file:$here/config/examples/hello.wav"
TOML
LIPSYNCD_DATA_DIR="$here/config" "$here/build/daemon/lipsyncd" --config "$tmp/lipsyncd.toml" 2>/dev/null &
pid=$!
for _ in $(seq 50); do [ -S "$tmp/control.sock" ] && break; sleep 0.1; done
ticks() { awk '{print $14 + $15}' "/proc/$pid/stat"; }
rss() { awk '/VmRSS/ {print $2}' "/proc/$pid/status"; }
hz=$(getconf CLK_TCK)
phase() {  # name seconds
  local t0 c0; t0=$(date +%s.%N); c0=$(ticks)
  sleep "$2"
  local t1 c1; t1=$(date +%s.%N); c1=$(ticks)
  echo "$1: CPU $(echo "scale=2; 100 * ($c1 - $c0) / $hz / ($t1 - $t0)" | bc) % of a core, RSS $(rss) KiB"
}
echo "started: RSS $(rss) KiB"
"$here/build/cli/lipsync" ctl --socket "$tmp/control.sock" status
for _ in $(seq 10); do "$here/build/cli/lipsync" ctl --socket "$tmp/control.sock" play "$here/config/examples/hello.wav" >/dev/null; done
phase "playing (10 x hello.wav queued)" 20
"$here/build/cli/lipsync" ctl --socket "$tmp/control.sock" status
phase "idle" 5
"$here/build/cli/lipsync" ctl --socket "$tmp/control.sock" live on >/dev/null
phase "live (hello.wav as the microphone, real-time pace)" 4
"$here/build/cli/lipsync" ctl --socket "$tmp/control.sock" live off >/dev/null
