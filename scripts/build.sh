#!/usr/bin/env bash
# Configures and builds lipsyncd into ./build (Release with debug info).
set -euo pipefail
cd "$(dirname "$0")/.."
"./scripts/install-deps.sh"
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo ${LIPSYNCD_CMAKE_ARGS:-} >/dev/null
cmake --build build -j"$(nproc)"
