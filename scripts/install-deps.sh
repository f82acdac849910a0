#!/usr/bin/env bash
# Installs the Debian 12 packages lipsyncd needs to build, test and run.
# Idempotent and quiet when everything is already there.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config
  libgpiod-dev gpiod libhidapi-dev libglm-dev
  libsndfile1-dev libsoxr-dev libespeak-ng-dev espeak-ng
  libasound2-dev libsystemd-dev systemd
  libtomlplusplus-dev nlohmann-json3-dev libcli11-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  clang libclang-rt-14-dev
  libcpp-httplib-dev chromium chromium-driver
  sox libsox-fmt-base libsox-fmt-mp3 pocketsphinx pocketsphinx-en-us  # labelling real speech (tests, training)
  ffmpeg  # the asterisk prompts' 16 kHz G.722 recordings, which the labeller aligns
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0

echo "install-deps: installing ${missing[*]}" >&2
sudo=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "install-deps: need root (or sudo) to install: ${missing[*]}" >&2; exit 1; }
  sudo="sudo"
fi
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq >/dev/null
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
