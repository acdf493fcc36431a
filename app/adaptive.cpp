#include "app/adaptive.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

#include "gl/cpu_reference.h"

namespace pxf {

std::vector<float> final_pixel_need(const Image& lv, const Image& hv, const Image& var_u, const Image& var_lv,
                                    const std::vector<uint32_t>& paths, float t) {
  std::vector<float> need(paths.size());
  for (size_t p = 0; p < need.size(); ++p) {
    // Var[L_lv + L_u] as Var[L_u] + Var[L_lv], unknown where either is.
    const float vu = clean_var(var_u.pixels[p]), vl = clean_var(var_lv.pixels[p]);
    const float t_n = effective_threshold(t, paths[p]);
    if (vu < 0.0f || vl < 0.0f || !(t_n > 0.0f)) {
      need[p] = std::numeric_limits<float>::infinity();
      continue;
    }
    const float lb = std::max(luminance(clean(hv.pixels[3 * p]), clean(hv.pixels[3 * p + 1]), clean(hv.pixels[3 * p + 2])) +
                                  luminance(clean(lv.pixels[3 * p]), clean(lv.pixels[3 * p + 1]), clean(lv.pixels[3 * p + 2])),
                              0.0f);
    need[p] = relative_variance(vu + vl, lb) / t_n;
  }
  return need;
}

std::vector<float> neighbourhood_need(const std::vector<float>& need, int width, int height, int radius) {
  std::vector<float> out(need.size());
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      float m = 0.0f;
      for (int qy = std::max(0, y - radius); qy <= std::min(height - 1, y + radius); ++qy)
        for (int qx = std::max(0, x - radius); qx <= std::min(width - 1, x + radius); ++qx)
          if (qx != x || qy != y) m = std::max(m, need[static_cast<size_t>(qy) * width + qx]);
      out[static_cast<size_t>(y) * width + x] = m;
    }
  return out;
}

namespace {

// The need at which a pixel is traced every frame: full_rate_need, or the need of the pixel at the
// top full_rate_share of `needs` where that is larger (nth_element: O(pixels)).
float full_rate_scale(std::vector<float> needs, const AdaptiveParams& params) {
  if (!(params.full_rate_share > 0.0f) || needs.empty()) return params.full_rate_need;
  // The pixel with share * n - 1 pixels above it: exactly the top share is at or past it.
  const size_t share_count = static_cast<size_t>(params.full_rate_share * static_cast<float>(needs.size()));
  const size_t top = std::min(needs.size(), std::max<size_t>(share_count, 1)) - 1;
  std::nth_element(needs.begin(), needs.begin() + top, needs.end(), std::greater<float>());
  const float at_share = needs[top];
  return std::isfinite(at_share) ? std::max(params.full_rate_need, at_share) : params.full_rate_need;
}

}  // namespace

std::vector<float> sampling_rates(const std::vector<float>& dilated_need, const std::vector<uint32_t>& paths,
                                  const AdaptiveParams& params) {
  std::vector<float> needs(dilated_need.size());
  for (size_t p = 0; p < needs.size(); ++p) {
    needs[p] = std::isnan(dilated_need[p]) ? std::numeric_limits<float>::infinity() : dilated_need[p];
    if (paths[p] < params.min_samples) needs[p] = std::max(needs[p], 1.0f);  // not retired on few samples
  }
  const float scale = full_rate_scale(needs, params);
  std::vector<float> rates(needs.size());
  for (size_t p = 0; p < rates.size(); ++p) rates[p] = std::clamp(needs[p] / scale, params.floor_rate, 1.0f);
  return rates;
}

std::vector<uint8_t> select_active(const std::vector<float>& rates, std::vector<float>& credit) {
  credit.resize(rates.size(), 0.0f);
  std::vector<uint8_t> active(rates.size());
  for (size_t p = 0; p < rates.size(); ++p) {
    credit[p] += rates[p];
    active[p] = credit[p] >= 1.0f;
    if (active[p]) credit[p] -= 1.0f;
  }
  return active;
}

SampleCounts sample_counts(const std::vector<uint32_t>& paths) {
  SampleCounts c;
  if (paths.empty()) return c;
  uint64_t sum = 0;
  c.min = paths[0];
  for (uint32_t n : paths) {
    sum += n;
    c.min = std::min(c.min, n);
    c.max = std::max(c.max, n);
  }
  c.mean = static_cast<double>(sum) / static_cast<double>(paths.size());
  return c;
}

}  // namespace pxf
