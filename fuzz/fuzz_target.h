// The entry point every harness in fuzz/ defines: libFuzzer calls it in the fuzz build
// (-DPXF_FUZZ=ON, clang), fuzz/replay_main.cpp calls it for each committed input in the normal build.
// A harness returns normally for any input that a reader accepts or refuses with pxf::Error; any
// other exception, a crash or a sanitizer report is a finding.
#pragma once
#include <cstddef>
#include <cstdint>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

namespace pxf::fuzz {
// Aborts (a finding) with a message on stderr when `condition` is false.
void check(bool condition, const char* what);
// Images read by the harnesses are bounded to this many float samples, so that a header asking for
// gigabytes is refused instead of allocated, and each input stays fast (4 MiB of floats at most).
constexpr size_t kMaxSamples = size_t{1} << 20;
}  // namespace pxf::fuzz
