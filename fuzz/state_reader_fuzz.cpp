// The accumulation-state reader (decode_state, the code path of read_state_file). The checksum stops
// almost every mutation at the door, so each input is decoded twice: as given, and with a correct
// checksum appended, which lets the fuzzer reach the counts, ranges and pixel arrays behind it.
// A state that decodes must encode back to the same bytes and merge with nothing but itself.
#include <cstring>
#include <vector>

#include "fuzz/fuzz_target.h"
#include "pathtracer/accumulation_state.h"

namespace {
void decode(const uint8_t* data, size_t size) {
  try {
    const pxf::AccumulationState state = pxf::decode_state(data, size);
    const std::vector<uint8_t> again = pxf::encode_state(state);
    pxf::fuzz::check(again.size() == size && std::memcmp(again.data(), data, size) == 0,
                     "a decoded state does not encode to the same bytes");
    const std::vector<float> variance = state.acc.variance_of_mean_image();
    pxf::fuzz::check(variance.size() == static_cast<size_t>(state.acc.width) * state.acc.height,
                     "variance image size");
    const pxf::AccumulationState merged = pxf::merge_states({state});
    pxf::fuzz::check(merged.frames == state.frames, "merging one state changed its frames");
  } catch (const pxf::Error&) {
  }
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  decode(data, size);
  std::vector<uint8_t> sealed(data, data + size);
  const uint64_t checksum = pxf::fnv1a64(data, size);
  const auto* bytes = reinterpret_cast<const uint8_t*>(&checksum);
  sealed.insert(sealed.end(), bytes, bytes + sizeof(checksum));
  decode(sealed.data(), sealed.size());
  return 0;
}
