#!/usr/bin/env bash
# Builds the libFuzzer target for the decoder-to-schedule path with clang (address and UB
# sanitizers) into ./build-fuzz, and fuzzes it for SECONDS (default 60) from fuzz/seeds.
# New inputs go to build-fuzz/corpus (the committed seeds are not touched); a crash leaves
# crash-* in build-fuzz/ and a non-zero exit. Reproduce one with: build/fuzz/fuzz_replay FILE
#
#   scripts/fuzz.sh [SECONDS]
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-60}"
"./scripts/install-deps.sh"
cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ \
  -DCMAKE_C_COMPILER=clang -DLIPSYNCD_FUZZ=ON -DLIPSYNCD_BUILD_TESTS=OFF -DLIPSYNCD_BUILD_BENCH=OFF >/dev/null
cmake --build build-fuzz -j"$(nproc)" --target fuzz_decode_schedule
mkdir -p build-fuzz/corpus
cd build-fuzz
LSAN_OPTIONS="suppressions=$PWD/../fuzz/lsan.supp" LIPSYNCD_DATA_DIR="$PWD/../config" ./fuzz/fuzz_decode_schedule corpus ../fuzz/seeds \
  -max_total_time="$seconds" -max_len=65536 -rss_limit_mb=2048 -print_final_stats=1 2>&1 | tail -n 15
