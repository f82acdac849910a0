#!/usr/bin/env bash
# Installs what is missing, builds, and runs the whole test suite: a short libFuzzer run of the
# decoder-to-schedule target (clang build in build-fuzz/; skip with LIPSYNCD_SKIP_FUZZ=1), then
# every test. ctest's summary line is the last thing this prints.
set -euo pipefail
cd "$(dirname "$0")/.."
"./scripts/build.sh"
if [ -z "${LIPSYNCD_SKIP_FUZZ:-}" ]; then
  "./scripts/fuzz.sh" "${LIPSYNCD_FUZZ_SECONDS:-20}"
fi
ctest --test-dir build --output-on-failure -j"$(nproc)" --timeout 300
