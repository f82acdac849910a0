#!/usr/bin/env bash
# Builds one libFuzzer target with clang (address and UB sanitizers) into ./build-fuzz, and
# fuzzes it for SECONDS (default 60) from its committed seeds. Targets (fuzz/CMakeLists.txt):
# decode_schedule (default), schedule, weights_csv, puppet_toml, curve_json, control.
# New inputs go to build-fuzz/corpus-TARGET (the committed seeds are not touched); a crash
# leaves crash-* in build-fuzz/ and a non-zero exit. Reproduce one with:
#   build/fuzz/fuzz_replay_TARGET FILE
#
#   scripts/fuzz.sh [SECONDS] [TARGET]
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-60}"
target="${2:-decode_schedule}"
seeds="../fuzz/seeds/$target"
[ "$target" = decode_schedule ] && seeds="../fuzz/seeds"
"./scripts/install-deps.sh"
cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ \
  -DCMAKE_C_COMPILER=clang -DLIPSYNCD_FUZZ=ON -DLIPSYNCD_BUILD_TESTS=OFF -DLIPSYNCD_BUILD_BENCH=OFF >/dev/null
cmake --build build-fuzz -j"$(nproc)" --target "fuzz_$target"
mkdir -p "build-fuzz/corpus-$target"
cd build-fuzz
LSAN_OPTIONS="suppressions=$PWD/../fuzz/lsan.supp" LIPSYNCD_DATA_DIR="$PWD/../config" "./fuzz/fuzz_$target" "corpus-$target" "$seeds" \
  -max_total_time="$seconds" -max_len=65536 -rss_limit_mb=2048 -print_final_stats=1 2>&1 | grep -v "# Uses:" | tail -n 15
