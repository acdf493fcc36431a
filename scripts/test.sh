#!/usr/bin/env bash
# Sets up and builds pxf, then runs the whole test suite with ctest. Afterwards it builds the
# core libraries' unit tests with AddressSanitizer + UndefinedBehaviorSanitizer and runs them
# (skip with PXF_SKIP_SANITIZERS=1).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
ctest --test-dir build --output-on-failure -j "$(nproc)" --timeout 600

if [ "${PXF_SKIP_SANITIZERS:-0}" != "1" ]; then
  echo "== unit tests under AddressSanitizer + UndefinedBehaviorSanitizer"
  PXF_BUILD_DIR=build-asan scripts/setup.sh -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPXF_SANITIZE=ON >/dev/null
  ASAN_OPTIONS=detect_leaks=0 ctest --test-dir build-asan --output-on-failure -j "$(nproc)" --timeout 900 \
    -L 'image_tests|pathtracer_tests'
fi
