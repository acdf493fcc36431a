// OpenEXR reader from memory (read_exr_layers_from_memory, the code path of read_exr): any bytes give
// layers of the declared size with finite-or-not floats, or a pxf::Error.
#include <cstdint>
#include <vector>

#include "fuzz/fuzz_target.h"
#include "image/image.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    const std::vector<pxf::Layer> layers = pxf::read_exr_layers_from_memory(data, size, "fuzz.exr", pxf::fuzz::kMaxSamples);
    pxf::fuzz::check(!layers.empty(), "EXR read without a layer");
    for (const pxf::Layer& layer : layers) {
      const pxf::Image& image = layer.image;
      pxf::fuzz::check(image.width > 0 && image.height > 0, "EXR layer with an empty size");
      pxf::fuzz::check(image.pixels.size() == image.pixel_count() * image.channels.size(), "EXR layer size mismatch");
      pxf::count_nonfinite(image);  // reads every pixel: uninitialized or out-of-range memory shows here
    }
  } catch (const pxf::Error&) {
  }
  return 0;
}
