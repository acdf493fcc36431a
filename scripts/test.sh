#!/usr/bin/env bash
# Sets up and builds pxf, then runs the whole test suite with ctest. Then, where clang++ and
# libFuzzer work, one clang build under AddressSanitizer + UndefinedBehaviorSanitizer (build-fuzz/,
# scripts/fuzz.sh) runs the core libraries' unit tests (core, image, scene, pathtracer; skip with
# PXF_SKIP_SANITIZERS=1) and a short libFuzzer run of each harness in fuzz/ (PXF_FUZZ_SECONDS per
# harness, default 10; skip with PXF_SKIP_FUZZ=1); any test failure, crash, leak, sanitizer report or
# timeout fails the script. One sanitizer build serves both: a second one of the libraries was
# about 4 of the script's 18 minutes on 2 cores.
set -euo pipefail
cd "$(dirname "$0")/.."
PXF_BUILD_TARGETS=all scripts/setup.sh
ctest --test-dir build --output-on-failure -j "$(nproc)" --timeout 600

sanitizers=1 fuzz=1
[ "${PXF_SKIP_SANITIZERS:-0}" != "1" ] || sanitizers=0
[ "${PXF_SKIP_FUZZ:-0}" != "1" ] || fuzz=0
if [ $((sanitizers + fuzz)) -gt 0 ] && ! scripts/fuzz.sh --available; then
  echo "== sanitizer tests and libFuzzer harnesses skipped: clang++ with libFuzzer not available (scripts/setup.sh installs it)"
  exit 0
fi
if [ $sanitizers = 1 ]; then
  echo "== core, image, scene and path tracer unit tests under AddressSanitizer + UndefinedBehaviorSanitizer (clang, build-fuzz/)"
  scripts/fuzz.sh --unit-tests
fi
if [ $fuzz = 1 ]; then
  echo "== libFuzzer harnesses, ${PXF_FUZZ_SECONDS:-10} s each (scripts/fuzz.sh)"
  scripts/fuzz.sh "${PXF_FUZZ_SECONDS:-10}"
fi
