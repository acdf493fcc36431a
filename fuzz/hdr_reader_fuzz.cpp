// Radiance HDR from memory. The input is read as given and, so that mutations of the pixel data are
// not wasted on a broken signature, once more behind a valid "#?RADIANCE" header line.
#include <string>
#include <vector>

#include "fuzz/ldr_hdr_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  pxf::fuzz::read_ldr_or_hdr_input(data, size, "fuzz.hdr");
  static const std::string signature = "#?RADIANCE\n";
  if (size < signature.size() || std::memcmp(data, signature.data(), signature.size()) != 0) {
    std::vector<uint8_t> with_signature(signature.begin(), signature.end());
    with_signature.insert(with_signature.end(), data, data + size);
    pxf::fuzz::read_ldr_or_hdr_input(with_signature.data(), with_signature.size(), "fuzz.hdr");
  }
  return 0;
}
