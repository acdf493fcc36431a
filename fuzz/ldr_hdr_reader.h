// The PNG and Radiance HDR harnesses share this body: both formats go through
// read_ldr_or_hdr_from_memory; they differ in their seed corpora and in which format they insist on.
#pragma once
#include <cstdint>
#include <cstring>

#include "fuzz/fuzz_target.h"
#include "image/image.h"

namespace pxf::fuzz {
inline void read_ldr_or_hdr_input(const uint8_t* data, size_t size, const char* name) {
  try {
    const Image image = read_ldr_or_hdr_from_memory(data, size, name, kMaxSamples);
    check(image.width > 0 && image.height > 0, "image with an empty size");
    check(image.num_channels() >= 1 && image.num_channels() <= 4, "image with 0 or more than 4 channels");
    check(image.pixels.size() == image.pixel_count() * image.channels.size(), "image size mismatch");
    count_nonfinite(image);
  } catch (const Error&) {
  }
}
}  // namespace pxf::fuzz
