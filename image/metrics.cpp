// SPEC section 4: one implementation of the error metrics for tests, `pxf bench` and `pxf diff`.
#include <cmath>
#include <cstdio>

#include "image/image.h"

namespace pxf {

namespace {
std::vector<std::pair<int, int>> shared_channels(const Image& test, const Image& reference) {
  std::vector<std::pair<int, int>> pairs;
  for (int c = 0; c < reference.num_channels(); ++c) {
    if (reference.channels[c] == "A") continue;
    int t = test.channel_index(reference.channels[c]);
    if (t >= 0) pairs.emplace_back(t, c);
  }
  return pairs;
}
}  // namespace

size_t count_nonfinite(const Image& image) {
  size_t count = 0;
  for (float v : image.pixels) count += std::isfinite(v) ? 0 : 1;
  return count;
}

ImageMetrics compare_images(const Image& test, const Image& reference) {
  if (test.width != reference.width || test.height != reference.height)
    throw Error("image sizes differ: " + std::to_string(test.width) + "x" + std::to_string(test.height) + " vs " +
                std::to_string(reference.width) + "x" + std::to_string(reference.height));
  const auto pairs = shared_channels(test, reference);
  if (pairs.empty()) throw Error("the images share no color channel");

  ImageMetrics m;
  double sum_sq = 0, sum_rel = 0, sum_ref = 0;
  const size_t tn = test.channels.size(), rn = reference.channels.size();
  for (size_t p = 0; p < reference.pixel_count(); ++p) {
    for (auto [t, r] : pairs) {
      const double tv = test.pixels[p * tn + t], rv = reference.pixels[p * rn + r];
      if (std::isnan(tv)) { ++m.nan_count; continue; }
      if (std::isinf(tv)) { ++m.inf_count; continue; }
      if (!std::isfinite(rv)) continue;  // a broken reference sample says nothing about the test
      const double d = tv - rv;
      sum_sq += d * d;
      sum_rel += d * d / (rv * rv + 1e-2);
      sum_ref += rv;
      m.max_abs_diff = std::max(m.max_abs_diff, std::abs(d));
      ++m.samples;
    }
  }
  if (m.samples == 0) return m;
  const double n = static_cast<double>(m.samples);
  m.rmse = std::sqrt(sum_sq / n);
  m.reference_mean = sum_ref / n;
  m.nrmse_percent = m.reference_mean > 0 ? 100.0 * m.rmse / m.reference_mean : (m.rmse > 0 ? INFINITY : 0.0);
  m.rel_mse = sum_rel / n;
  return m;
}

std::string format_metrics(const ImageMetrics& m) {
  char line[512];
  std::snprintf(line, sizeof line,
                "NRMSE %.4f %%  RMSE %.6g  relMSE %.6g  max|diff| %.6g  reference mean %.6g  NaN %zu  Inf %zu  samples %zu",
                m.nrmse_percent, m.rmse, m.rel_mse, m.max_abs_diff, m.reference_mean, m.nan_count, m.inf_count,
                m.samples);
  return line;
}

}  // namespace pxf
