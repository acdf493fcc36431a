#include "exr_writer.h"

#include <ImfRgbaFile.h>

#include <algorithm>
#include <exception>

namespace pxf::scenegen {

bool writeExrRgb(const std::string& path, const FloatImage& rgb, std::string* error) {
  if (rgb.channels != 3) {
    *error = path + ": environment image must have 3 channels";
    return false;
  }
  std::vector<Imf::Rgba> pixels(size_t(rgb.width) * rgb.height);
  for (size_t i = 0; i < pixels.size(); ++i) {
    // Half floats overflow to infinity above 65504; the sky never needs more.
    auto toHalf = [](float v) { return half(std::clamp(v, 0.0f, 60000.0f)); };
    pixels[i] = Imf::Rgba(toHalf(rgb.data[3 * i]), toHalf(rgb.data[3 * i + 1]), toHalf(rgb.data[3 * i + 2]), 1.0f);
  }
  try {
    Imf::RgbaOutputFile file(path.c_str(), rgb.width, rgb.height, Imf::WRITE_RGB, 1.0f, Imath::V2f(0, 0), 1.0f,
                             Imf::INCREASING_Y, Imf::ZIP_COMPRESSION);
    file.setFrameBuffer(pixels.data(), 1, size_t(rgb.width));
    file.writePixels(rgb.height);
  } catch (const std::exception& e) {
    *error = path + ": " + e.what();
    return false;
  }
  return true;
}

}  // namespace pxf::scenegen
