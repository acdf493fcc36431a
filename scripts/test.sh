#!/usr/bin/env bash
# Sets up and builds pxf, then runs the whole test suite with ctest. Afterwards it builds the
# core libraries' unit tests (image, pathtracer) with AddressSanitizer + UndefinedBehaviorSanitizer
# in build-asan/ and runs them (skip with PXF_SKIP_SANITIZERS=1). Last, a short libFuzzer run of each
# harness in fuzz/ (PXF_FUZZ_SECONDS per harness, default 10; skip with PXF_SKIP_FUZZ=1) where clang++
# and libFuzzer work; any crash, leak, sanitizer report or timeout fails the script.
set -euo pipefail
cd "$(dirname "$0")/.."
PXF_BUILD_TARGETS=all scripts/setup.sh
ctest --test-dir build --output-on-failure -j "$(nproc)" --timeout 600

if [ "${PXF_SKIP_SANITIZERS:-0}" != "1" ]; then
  echo "== image and path tracer unit tests under AddressSanitizer + UndefinedBehaviorSanitizer"
  # -O1 -g1 (line tables, no locals): the reports keep their file:line stacks, and the build, the
  # longest step of this script on CI's 2 cores, takes less than at -O2 -g.
  [ -f build-asan/CMakeCache.txt ] ||
    cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" \
      -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -g1" -DPXF_SANITIZE=ON >/dev/null
  cmake --build build-asan -j "$(nproc)" --target image_tests pathtracer_tests
  ASAN_OPTIONS=detect_leaks=0 ctest --test-dir build-asan --output-on-failure -j "$(nproc)" --timeout 900 \
    -L 'image_tests|pathtracer_tests'
fi

if [ "${PXF_SKIP_FUZZ:-0}" != "1" ]; then
  if scripts/fuzz.sh --available; then
    echo "== libFuzzer harnesses, ${PXF_FUZZ_SECONDS:-10} s each (scripts/fuzz.sh)"
    scripts/fuzz.sh "${PXF_FUZZ_SECONDS:-10}"
  else
    echo "== libFuzzer harnesses skipped: clang++ with libFuzzer not available (scripts/setup.sh installs it)"
  fi
fi
