#!/usr/bin/env bash
# Regenerates the README's screenshots of `lipsync edit` (docs/images/editor-*.png): the
# end-to-end test drives the editor in headless chromium and saves them where it is told.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
build="${BUILD:-$here/build}"
cmake --build "$build" --target editor_tests lipsync
mkdir -p "$here/docs/images"
LIPSYNCD_DATA_DIR="$here/config" LIPSYNCD_SCREENSHOT_DIR="$here/docs/images" \
  "$build/tests/editor_tests" --gtest_filter='EditorBrowser.*'
