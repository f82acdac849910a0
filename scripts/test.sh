#!/usr/bin/env bash
# Installs what is missing, builds, and runs the whole test suite.
# ctest's summary line is the last thing this prints.
set -euo pipefail
cd "$(dirname "$0")/.."
"./scripts/build.sh"
ctest --test-dir build --output-on-failure -j"$(nproc)" --timeout 300
