// PNG (and whatever else stb recognizes: JPEG, BMP, ...) from memory.
#include "fuzz/ldr_hdr_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  pxf::fuzz::read_ldr_or_hdr_input(data, size, "fuzz.png");
  return 0;
}
