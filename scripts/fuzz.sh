#!/usr/bin/env bash
# libFuzzer campaigns on the harnesses of fuzz/ (docs/fuzzing.md), built with clang under
# AddressSanitizer + UndefinedBehaviorSanitizer in build-fuzz/ (-DPXF_FUZZ=ON). The normal gcc build
# is not touched.
#   scripts/fuzz.sh [SECONDS_PER_HARNESS] [HARNESS...]   fuzz each harness (default 600 s, all of them)
#   scripts/fuzz.sh --replay [HARNESS...]                 every committed input once, under the sanitizers
#   scripts/fuzz.sh --merge [HARNESS...]                  minimize: merge what the campaigns found
#                                                         (build-fuzz/corpus/) into fuzz/corpus/
#   scripts/fuzz.sh --unit-tests                          the core, image, scene and path tracer unit tests, built in
#                                                         the same folder, so under the same sanitizers
#   scripts/fuzz.sh --available                           exit 0 when clang++ and libFuzzer work here
# Harnesses: gltf_scene exr_reader png_reader hdr_reader state_reader camera_path. Each campaign reads the committed
# corpus (fuzz/corpus/H) and crashers (fuzz/crashers/H), writes new inputs to build-fuzz/corpus/H and
# its log to build-fuzz/logs/H.log, and any finding to build-fuzz/artifacts/H/. The script exits
# non-zero on any crash, leak, sanitizer report, timeout or out-of-memory.
# Environment: PXF_FUZZ_RSS_MB (2048), PXF_FUZZ_TIMEOUT (per input, s, 10), PXF_JOBS (build jobs).
set -euo pipefail
cd "$(dirname "$0")/.."

ALL=(gltf_scene exr_reader png_reader hdr_reader state_reader camera_path)
BUILD=build-fuzz
RSS_MB="${PXF_FUZZ_RSS_MB:-2048}"
TIMEOUT="${PXF_FUZZ_TIMEOUT:-10}"

find_clang() {
  for c in clang++ clang++-14; do
    command -v "$c" >/dev/null 2>&1 && { echo "$c"; return 0; }
  done
  return 1
}

available() {
  local cxx tmp
  cxx="$(find_clang)" || return 1
  tmp="$(mktemp -d)"
  printf 'extern "C" int LLVMFuzzerTestOneInput(const unsigned char*, unsigned long) { return 0; }\n' >"$tmp/t.cpp"
  "$cxx" -fsanitize=fuzzer,address,undefined "$tmp/t.cpp" -o "$tmp/t" >/dev/null 2>&1 && "$tmp/t" -runs=1 >/dev/null 2>&1
  local rc=$?
  rm -rf "$tmp"
  return $rc
}

mode=fuzz
case "${1:-}" in
  --available) available; exit $? ;;
  --replay) mode=replay; shift ;;
  --merge) mode=merge; shift ;;
  --unit-tests) mode=unit; shift ;;
esac
seconds=600
if [ "$mode" = fuzz ] && [[ "${1:-}" =~ ^[0-9]+$ ]]; then seconds="$1"; shift; fi
harnesses=("$@")
[ ${#harnesses[@]} -gt 0 ] || harnesses=("${ALL[@]}")

if ! available; then
  echo "fuzz: clang++ with libFuzzer not found or not working (scripts/setup.sh installs clang-14 and libfuzzer-14-dev)" >&2
  exit 2
fi
CXX_FUZZ="$(find_clang)"
CC_FUZZ="${CXX_FUZZ/clang++/clang}"
if [ ! -f "$BUILD/CMakeCache.txt" ]; then
  launcher=()
  command -v ccache >/dev/null 2>&1 && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
  # The test programs' own code at -O0: under the sanitizers it compiles in half the time of -O1,
  # and their work is in the libraries (CMakeLists.txt, PXF_TEST_CODE_OPTIMIZATION).
  cmake -S . -B "$BUILD" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER="$CXX_FUZZ" -DCMAKE_C_COMPILER="$CC_FUZZ" \
    -DPXF_FUZZ=ON -DPXF_BUILD_TESTS=ON -DPXF_TEST_CODE_OPTIMIZATION=-O0 "${launcher[@]}" >/dev/null
fi
if [ "$mode" = unit ]; then
  # A folder configured before the unit tests were built here (PXF_BUILD_TESTS=OFF) gets them now.
  grep -q '^PXF_BUILD_TESTS:BOOL=ON' "$BUILD/CMakeCache.txt" ||
    cmake -S . -B "$BUILD" -DPXF_BUILD_TESTS=ON -DPXF_TEST_CODE_OPTIMIZATION=-O0 >/dev/null
  # The libraries' coverage instrumentation (-fsanitize=fuzzer-no-link) costs these tests about a
  # third more time, less than a second sanitizer build of the libraries would. Leaks are not
  # findings here: the tests' process-lifetime objects (the GL context, TBB's arenas) are not freed.
  # Left out here, not in the normal build: three image statistics over thousands of paths (a large
  # share of these tests' time under the sanitizers), whose code paths the furnace and
  # restored-field tests run here too.
  cmake --build "$BUILD" -j "${PXF_JOBS:-$(nproc)}" --target core_tests image_tests scene_tests pathtracer_tests
  ASAN_OPTIONS=detect_leaks=0 ctest --test-dir "$BUILD" --output-on-failure -j "$(nproc)" --timeout 900 \
    -L 'core_tests|image_tests|scene_tests|pathtracer_tests' \
    -E '^(SpecularSampling.CornellMeansAgreeWithoutIt|Guiding.GuidedImageAgreesWithUnguidedReference|Guiding.TrainedFieldFindsTheMirrorCaustic)$'
  exit
fi
targets=()
for h in "${harnesses[@]}"; do targets+=("${h}_fuzz"); done
cmake --build "$BUILD" -j "${PXF_JOBS:-$(nproc)}" --target "${targets[@]}"

# Leaks are findings; UBSan stops at the first report (-fno-sanitize-recover) with a stack.
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=0}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"

failed=()
total=0
for h in "${harnesses[@]}"; do
  bin="$BUILD/fuzz/${h}_fuzz"
  dict=()
  [ -f "fuzz/${h%%_*}.dict" ] && dict=("-dict=fuzz/${h%%_*}.dict")
  mkdir -p "$BUILD/corpus/$h" "$BUILD/artifacts/$h" "$BUILD/logs"
  log="$BUILD/logs/$h.log"
  case "$mode" in
    replay)
      echo "== $h: every committed input once"
      if ! "$bin" -rss_limit_mb="$RSS_MB" -timeout="$TIMEOUT" -runs=0 fuzz/corpus/"$h" fuzz/crashers/"$h" >"$log" 2>&1; then
        failed+=("$h"); tail -n 30 "$log"
      fi ;;
    merge)
      echo "== $h: merging build-fuzz/corpus/$h into fuzz/corpus/$h"
      "$bin" -merge=1 -rss_limit_mb="$RSS_MB" -timeout="$TIMEOUT" "${dict[@]}" fuzz/corpus/"$h" "$BUILD/corpus/$h" >"$log" 2>&1 ||
        { failed+=("$h"); tail -n 30 "$log"; } ;;
    fuzz)
      echo "== $h: fuzzing for $seconds s (log: $log)"
      if ! "$bin" -max_total_time="$seconds" -rss_limit_mb="$RSS_MB" -timeout="$TIMEOUT" -print_final_stats=1 \
          -artifact_prefix="$BUILD/artifacts/$h/" "${dict[@]}" \
          "$BUILD/corpus/$h" fuzz/corpus/"$h" fuzz/crashers/"$h" >"$log" 2>&1; then
        failed+=("$h")
        grep -E "ERROR|SUMMARY|runtime error|fuzz check failed|Test unit written" "$log" | head -n 20 || true
      fi
      runs="$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)"
      echo "   $h: ${runs:-?} executions, $(ls "$BUILD/corpus/$h" | wc -l) new corpus inputs"
      total=$((total + ${runs:-0})) ;;
  esac
done
[ "$mode" = fuzz ] && echo "fuzz: $total executions in all"
if [ ${#failed[@]} -gt 0 ]; then
  echo "fuzz: FINDINGS in ${failed[*]} (inputs in $BUILD/artifacts/; copy each to fuzz/crashers/HARNESS/ once fixed)" >&2
  exit 1
fi
echo "fuzz: no finding"
