#include "image/tonemap.h"

#include <algorithm>
#include <cmath>

#include "shaders/tonemap_formulas.h"

namespace pxf {

namespace {
float sanitize_display(float v) { return std::isfinite(v) ? std::clamp(v, 0.0f, kMaxTonemapInput) : 0.0f; }

struct Rgb {
  float c[3];
  float luminance() const { return pxf::luminance(c[0], c[1], c[2]); }
};
Rgb display_input(const Image& rgb, int x, int y) {
  return {{sanitize_display(rgb.at(x, y, 0)), sanitize_display(rgb.at(x, y, 1)), sanitize_display(rgb.at(x, y, 2))}};
}
}  // namespace

double log_average_luminance(const Image& rgb, float delta) {
  double sum = 0;
  for (int y = 0; y < rgb.height; ++y)
    for (int x = 0; x < rgb.width; ++x) sum += std::log(double(delta) + display_input(rgb, x, y).luminance());
  return std::exp(sum / std::max<size_t>(rgb.pixel_count(), 1));
}

Image tonemap_reinhard(const Image& rgb, const TonemapParams& p) {
  Image out = Image::rgb(rgb.width, rgb.height);
  const double lavg = p.log_average > 0 ? p.log_average : log_average_luminance(rgb, p.delta);
  const float k = static_cast<float>(p.key / std::max(lavg, 1e-30));
  for (int y = 0; y < rgb.height; ++y)
    for (int x = 0; x < rgb.width; ++x) {
      const Rgb c = display_input(rgb, x, y);
      const float scale = shared::reinhard_scale(k, c.luminance(), p.white);
      for (int i = 0; i < 3; ++i) out.at(x, y, i) = srgb_from_linear(std::clamp(c.c[i] * scale, 0.0f, 1.0f));
    }
  return out;
}

}  // namespace pxf
