#!/usr/bin/env bash
# Measures the running daemon (the built build/daemon/lipsyncd, null audio device, terminal
# puppet, no hardware). Two measurements:
#
#   scripts/measure-daemon.sh [cpu]
#     CPU and memory while it plays the bundled example ten times, then idle, then live (the
#     bundled example as the microphone). One line per phase, and the status (latency).
#
#   scripts/measure-daemon.sh memory [SECONDS] [MIX]
#     Memory with a full queue of maximum-length clips (issue 12: under 24 MB). The default
#     limits (max_queue 8, max_clip_seconds 30, max_text_bytes 600); requests are queued until
#     the daemon says the queue is full: 30 s clips of 48 kHz stereo speech (the most samples a
#     clip may hold) and 600-byte `say` texts (MIX: both, the default; play; say). /proc is
#     sampled every 100 ms for SECONDS (default 45: the first clip plays, the next is
#     prepared): idle RSS, the highest RSS seen, VmHWM (the kernel's own peak), and the bytes
#     the clips hold (status "memory"). LIPSYNCD may name a wrapper (e.g. "heaptrack -o F
#     build/daemon/lipsyncd").
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
mode="${1:-cpu}"
lipsyncd="${LIPSYNCD:-$here/build/daemon/lipsyncd}"
tmp="$(mktemp -d)"
pid=""
trap '[ -n "$pid" ] && kill "$pid" 2>/dev/null; rm -rf "$tmp"' EXIT
cat >"$tmp/lipsyncd.toml" <<TOML
[audio]
device = "null"
[mouth]
puppet = "terminal"
hardware = false
[control]
socket = "$tmp/control.sock"
[live]
device = "file:$here/config/examples/hello.wav"
TOML
[ "$mode" = cpu ] && printf '[limits]\nmax_queue = 16\n' >>"$tmp/lipsyncd.toml"
LIPSYNCD_DATA_DIR="$here/config" $lipsyncd --config "$tmp/lipsyncd.toml" 2>"$tmp/log" &
pid=$!
for _ in $(seq 100); do [ -S "$tmp/control.sock" ] && break; sleep 0.1; done
ctl() { "$here/build/cli/lipsync" ctl --socket "$tmp/control.sock" "$@"; }
field() { awk -v k="$1:" '$1 == k {print $2}' "/proc/$pid/status"; }
ticks() { awk '{print $14 + $15}' "/proc/$pid/stat"; }
hz=$(getconf CLK_TCK)
phase() {  # name seconds
  local t0 c0; t0=$(date +%s.%N); c0=$(ticks)
  sleep "$2"
  local t1 c1; t1=$(date +%s.%N); c1=$(ticks)
  echo "$1: CPU $(echo "scale=2; 100 * ($c1 - $c0) / $hz / ($t1 - $t0)" | bc) % of a core, RSS $(field VmRSS) KiB"
}

if [ "$mode" = cpu ]; then
  echo "started: RSS $(field VmRSS) KiB"
  ctl status
  for _ in $(seq 10); do ctl play "$here/config/examples/hello.wav" >/dev/null; done
  phase "playing (10 x hello.wav queued)" 20
  ctl status
  phase "idle" 5
  ctl live on >/dev/null
  phase "live (hello.wav as the microphone, real-time pace)" 4
  ctl status
  ctl live off >/dev/null
  exit 0
fi

[ "$mode" = memory ] || { echo "usage: $0 [cpu | memory [SECONDS] [both|play|say]]" >&2; exit 2; }
seconds="${2:-45}"
mix="${3:-both}"
# A maximum-length clip: the bundled example repeated to 30 s, 48 kHz, two channels.
sox "$here/config/examples/hello.wav" -r 48000 -c 2 "$tmp/long.wav" repeat 30 trim 0 30
text="$(printf 'The quick brown fox jumps over the lazy dog, then naps in the sun. %.0s' $(seq 9))"
text="${text:0:600}"
sleep 1
echo "idle: VmRSS $(field VmRSS) KiB"
queued=0
for i in $(seq 20); do
  if [ "$mix" = play ] || { [ "$mix" = both ] && [ $((i % 2)) -eq 1 ]; }; then
    r="$(ctl play "$tmp/long.wav" 2>&1 || true)"
  else
    r="$(ctl say "$text" 2>&1 || true)"
  fi
  case "$r" in *full*) break ;; *'"ok":false'*|*rror*) echo "refused: $r" >&2; exit 1 ;; esac
  queued=$((queued + 1))
done
echo "queued: $queued requests ($mix) until the queue was full"
peak=0
end=$(( $(date +%s) + seconds ))
while [ "$(date +%s)" -lt "$end" ]; do
  rss=$(field VmRSS); [ "$rss" -gt "$peak" ] && peak=$rss
  sleep 0.1
done
echo "full queue, ${seconds} s: highest VmRSS $peak KiB, VmHWM $(field VmHWM) KiB, threads $(field Threads)"
ctl status | grep -o '"memory":{[^}]*}'
