// docs/metrics.md: one implementation of the error metrics for tests, `pxf bench` and `pxf diff`.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>

#include "image/flip.h"
#include "image/image.h"
#include "image/metrics.h"
#include "image/tonemap.h"

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
void check_same_size(const Image& a, const Image& b, const char* what) {
  if (a.width != b.width || a.height != b.height)
    throw Error(std::string(what) + " sizes differ: " + std::to_string(a.width) + "x" + std::to_string(a.height) +
                " vs " + std::to_string(b.width) + "x" + std::to_string(b.height));
}

bool masked_out(const Image* mask, size_t pixel) {
  return mask && mask->pixels[pixel * mask->channels.size()] > 0;  // NaN in a mask keeps the pixel
}
}  // namespace

size_t count_nonfinite(const Image& image) {
  size_t count = 0;
  for (float v : image.pixels) count += std::isfinite(v) ? 0 : 1;
  return count;
}

void check_reference(const Image& reference, const std::string& path) {
  const size_t nonfinite = count_nonfinite(reference);
  if (nonfinite > 0)
    throw Error(path + ": " + std::to_string(nonfinite) + " non-finite samples (NaN or Inf); it cannot serve as a reference");
}

ImageMetrics compare_images(const Image& test, const Image& reference, const Image* mask) {
  check_same_size(test, reference, "image");
  if (mask) {
    check_same_size(*mask, reference, "mask and image");
    if (mask->channels.empty()) throw Error("the mask has no channel");
  }
  const auto pairs = shared_channels(test, reference);
  if (pairs.empty()) throw Error("the images share no color channel");

  ImageMetrics m;
  double sum_sq = 0, sum_rel = 0, sum_ref = 0, sum_test = 0;
  const size_t tn = test.channels.size(), rn = reference.channels.size();
  for (size_t p = 0; p < reference.pixel_count(); ++p) {
    if (masked_out(mask, p)) continue;
    for (auto [t, r] : pairs) {
      const double tv = test.pixels[p * tn + t], rv = reference.pixels[p * rn + r];
      if (std::isnan(tv)) { ++m.nan_count; continue; }
      if (std::isinf(tv)) { ++m.inf_count; continue; }
      if (!std::isfinite(rv)) {  // a broken reference sample says nothing about the test
        ++m.reference_nonfinite;
        continue;
      }
      const double d = tv - rv;
      sum_sq += d * d;
      sum_rel += d * d / (rv * rv + 1e-2);
      sum_ref += rv;
      sum_test += tv;
      m.max_abs_diff = std::max(m.max_abs_diff, std::abs(d));
      ++m.samples;
    }
  }
  if (m.samples == 0 && m.reference_nonfinite > 0)
    throw Error("the reference has no finite sample to compare against (" + std::to_string(m.reference_nonfinite) +
                " NaN/Inf)");
  if (m.samples == 0) return m;
  const double n = static_cast<double>(m.samples);
  m.rmse = std::sqrt(sum_sq / n);
  m.reference_mean = sum_ref / n;
  m.test_mean = sum_test / n;
  m.nrmse_percent = m.reference_mean > 0 ? 100.0 * m.rmse / m.reference_mean : (m.rmse > 0 ? INFINITY : 0.0);
  m.rel_mse = sum_rel / n;
  return m;
}

std::vector<double> pixel_squared_errors(const Image& test, const Image& reference) {
  check_same_size(test, reference, "image");
  const auto pairs = shared_channels(test, reference);
  if (pairs.empty()) throw Error("the images share no color channel");
  const size_t tn = test.channels.size(), rn = reference.channels.size();
  std::vector<double> errors(reference.pixel_count(), 0.0);
  for (size_t p = 0; p < errors.size(); ++p)
    for (auto [t, r] : pairs) {
      const double d = static_cast<double>(test.pixels[p * tn + t]) - reference.pixels[p * rn + r];
      if (std::isfinite(d)) errors[p] += d * d;
    }
  return errors;
}

double worst_pixels_share(std::vector<double> squared_errors, double fraction) {
  const double total = total_squared_error(squared_errors);
  if (!(total > 0)) return 0.0;
  const size_t count = std::min(squared_errors.size(),
                                static_cast<size_t>(std::ceil(std::clamp(fraction, 0.0, 1.0) * squared_errors.size())));
  std::nth_element(squared_errors.begin(), squared_errors.begin() + count, squared_errors.end(), std::greater<>());
  double worst = 0;
  for (size_t i = 0; i < count; ++i) worst += squared_errors[i];
  return worst / total;
}

double masked_squared_error(const std::vector<double>& squared_errors, const Image& mask) {
  if (mask.pixel_count() != squared_errors.size() || mask.channels.empty())
    throw Error("the mask does not match the image");
  double sum = 0;
  for (size_t p = 0; p < squared_errors.size(); ++p)
    if (mask.pixels[p * mask.channels.size()] > 0) sum += squared_errors[p];
  return sum;
}

double total_squared_error(const std::vector<double>& squared_errors) {
  double sum = 0;
  for (double e : squared_errors) sum += e;
  return sum;
}

std::string format_metrics(const ImageMetrics& m) {
  char line[512];
  std::snprintf(line, sizeof line,
                "NRMSE %.4f %%  RMSE %.6g  relMSE %.6g  max|diff| %.6g  reference mean %.6g  mean ratio %.5f  NaN %zu  "
                "Inf %zu  samples %zu",
                m.nrmse_percent, m.rmse, m.rel_mse, m.max_abs_diff, m.reference_mean,
                m.reference_mean > 0 ? m.test_mean / m.reference_mean : 1.0, m.nan_count, m.inf_count, m.samples);
  return line;
}

namespace {
double masked_mean(const Image& values, const Image* mask) {
  double sum = 0;
  size_t n = 0;
  for (size_t p = 0; p < values.pixel_count(); ++p) {
    if (masked_out(mask, p)) continue;
    sum += values.pixels[p];
    ++n;
  }
  return n ? sum / n : 0.0;
}
}  // namespace

OutlierMetrics count_outliers(const Image& test, const Image& reference, const Image* mask,
                              const OutlierOptions& options, std::vector<size_t>* where) {
  check_same_size(test, reference, "image");
  if (mask) {
    check_same_size(*mask, reference, "mask and image");
    if (mask->channels.empty()) throw Error("the mask has no channel");
  }
  const Image t = test.select({"R", "G", "B"}), r = reference.select({"R", "G", "B"});
  auto y = [](const Image& im, size_t p) {
    return static_cast<double>(luminance(im.pixels[3 * p], im.pixels[3 * p + 1], im.pixels[3 * p + 2]));
  };
  double sum = 0;
  size_t judged = 0;
  for (size_t p = 0; p < r.pixel_count(); ++p) {
    if (masked_out(mask, p) || !std::isfinite(y(r, p))) continue;
    sum += y(r, p);
    ++judged;
  }
  OutlierMetrics m;
  m.pixels = judged;
  if (where) where->clear();
  if (judged == 0) return m;
  m.luminance_floor = options.floor_fraction * sum / static_cast<double>(judged);
  for (size_t p = 0; p < r.pixel_count(); ++p) {
    const double ry = y(r, p), ty = y(t, p);
    if (masked_out(mask, p) || !std::isfinite(ry)) continue;
    if (!std::isfinite(ty) || ty > options.factor * std::max(ry, m.luminance_floor)) {
      ++m.outliers;
      if (where) where->push_back(p);
    }
  }
  m.fraction = static_cast<double>(m.outliers) / static_cast<double>(judged);
  return m;
}

DisplayImages tonemap_like_reference(const Image& test, const Image& reference, float key) {
  TonemapParams params;
  params.key = key;
  params.log_average = static_cast<float>(log_average_luminance(reference, params.delta));
  return {tonemap_reinhard(test, params), tonemap_reinhard(reference, params)};
}

DisplayMetrics compare_display(const Image& test, const Image& reference, const Image* mask,
                               const DisplayMetricOptions& options) {
  DisplayMetrics m;
  m.hdr = compare_images(test, reference, mask);
  const Image test_rgb = test.select({"R", "G", "B"}), reference_rgb = reference.select({"R", "G", "B"});
  const DisplayImages display = tonemap_like_reference(test_rgb, reference_rgb, options.key);
  m.display_nrmse_percent = compare_images(display.test, display.reference, mask).nrmse_percent;
  m.flip_mean = masked_mean(flip_error_map(display.test, display.reference, options.pixels_per_degree), mask);
  return m;
}

ReferenceNoiseCorrection correct_for_reference_noise(double test_nrmse_percent, double references_nrmse_percent) {
  ReferenceNoiseCorrection c;
  const double noise_squared = 0.5 * references_nrmse_percent * references_nrmse_percent;
  const double excess = test_nrmse_percent * test_nrmse_percent - noise_squared;
  c.reference_noise_percent = std::sqrt(noise_squared);
  c.within_reference_noise = !(excess > 0);
  c.corrected_percent = c.within_reference_noise ? 0.0 : std::sqrt(excess);
  return c;
}

}  // namespace pxf
