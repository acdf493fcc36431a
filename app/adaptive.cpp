#include "app/adaptive.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "gl/cpu_reference.h"

namespace pxf {

std::vector<float> final_pixel_need(const Image& lv, const Image& hv, const Image& var_u, const Image& var_lv,
                                    const std::vector<uint32_t>& paths, float t, const Image* range_color,
                                    const Image* depth, const RangeWeights& range, float exact_below) {
  const int w = hv.width, h = hv.height;
  // Var[L_lv + L_u] as Var[L_u] + Var[L_lv], unknown where either is: the image the pooling reads.
  Image var_final = Image::gray(w, h);
  for (size_t p = 0; p < var_final.pixels.size(); ++p) {
    const float vu = clean_var(var_u.pixels[p]), vl = clean_var(var_lv.pixels[p]);
    var_final.pixels[p] = vu < 0.0f || vl < 0.0f ? kVarUnknown : vu + vl;
  }
  const bool pool = range_color && depth;
  std::vector<float> need(var_final.pixels.size());
  // Rows in parallel: each pixel's need reads the inputs only, so the result is the same whatever
  // the thread count. The 3x3 range-weighted pooling is most of the allocation's cost.
  tbb::parallel_for(tbb::blocked_range<int>(0, h, 8), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y != rows.end(); ++y)
      for (int x = 0; x < w; ++x) {
        const size_t p = static_cast<size_t>(y) * w + x;
        const float t_n = effective_threshold(t, paths[p]);
        const float own = var_final.pixels[p];
        if (own < 0.0f || !(t_n > 0.0f)) {
          need[p] = std::numeric_limits<float>::infinity();
          continue;
        }
        const float lb = std::max(luminance(clean(hv.at(x, y, 0)), clean(hv.at(x, y, 1)), clean(hv.at(x, y, 2))) +
                                      luminance(clean(lv.at(x, y, 0)), clean(lv.at(x, y, 1)), clean(lv.at(x, y, 2))),
                                  0.0f);
        need[p] = relative_variance(own, lb) / t_n;
        if (pool && need[p] < exact_below)
          need[p] = relative_variance(pooled_var_u(var_final, *range_color, *depth, x, y, range), lb) / t_n;
      }
  });
  return need;
}

namespace {

// out = the largest value of `in` within `radius` cells along one axis: `lines` lines of `count`
// cells, `step` apart in the array, the lines `line_step` apart.
void window_max(const std::vector<float>& in, std::vector<float>& out, int count, int step, int lines, int line_step,
                int radius) {
  for (int line = 0; line < lines; ++line)
    for (int i = 0; i < count; ++i) {
      float m = -std::numeric_limits<float>::infinity();
      for (int q = std::max(0, i - radius); q <= std::min(count - 1, i + radius); ++q)
        m = std::max(m, in[static_cast<size_t>(line) * line_step + static_cast<size_t>(q) * step]);
      out[static_cast<size_t>(line) * line_step + static_cast<size_t>(i) * step] = m;
    }
}

}  // namespace

std::vector<float> dilate_need(const std::vector<float>& need, int width, int height, int radius) {
  // Separable: the largest value along each row's window, then along each column's.
  std::vector<float> rows(need.size()), out(need.size());
  window_max(need, rows, width, 1, height, width, radius);
  window_max(rows, out, height, width, width, 1, radius);
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
