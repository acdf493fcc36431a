#include "app/adaptive.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "gl/cpu_reference.h"
#include "pathtracer/pathtracer.h"

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

// w_p of goal Error (app/adaptive.h): s_p = sqrt(r_p n_p), the per-path relative deviation over
// sqrt(t) (r falls as 1/n).
float allocation_weight(float need, uint32_t paths, const AdaptiveParams& params) {
  const float n = static_cast<float>(std::max<uint32_t>(paths, 1));
  if (paths < params.min_samples) need = std::max(need, 1.0f);  // not retired on few samples
  return std::sqrt(need * n);
}

// The sum of the rates once each is raised to at least `level`.
double sum_raised_to(const std::vector<float>& rates, double level) {
  double sum = 0;
  for (float r : rates) sum += std::max(r, static_cast<float>(level));
  return sum;
}

}  // namespace

// The sum of the rates grows with lambda: lambda is found by bisection on its logarithm.
std::vector<float> water_fill(const std::vector<float>& weights, double total, float floor_rate, float max_rate) {
  auto rates_for = [&](double lambda, std::vector<float>* out) {
    double sum = 0;
    for (size_t p = 0; p < weights.size(); ++p) {
      const double w = weights[p];
      const float rate = std::isinf(w) ? max_rate : static_cast<float>(std::clamp(lambda * w, double{floor_rate}, double{max_rate}));
      if (out) (*out)[p] = rate;
      sum += rate;
    }
    return sum;
  };
  double lo = 1e-30, hi = 1e30;
  for (int i = 0; i < 200 && hi / lo > 1.0 + 1e-7; ++i) {
    const double mid = std::sqrt(lo * hi);
    (rates_for(mid, nullptr) < total ? lo : hi) = mid;
  }
  std::vector<float> rates(weights.size());
  if (rates_for(hi, &rates) >= total) {
    rates_for(lo, &rates);
    return rates;
  }
  // The weights cannot take the paths (every weighted pixel at max_rate): the rest go to every
  // pixel alike, the floor rising by bisection until the rates add up (or all are at max_rate).
  double level_lo = floor_rate, level_hi = max_rate;
  if (sum_raised_to(rates, max_rate) <= total) level_lo = max_rate;  // a budget past every cap
  for (int i = 0; i < 100 && level_hi - level_lo > 1e-7 * level_hi; ++i) {
    const double mid = 0.5 * (level_lo + level_hi);
    (sum_raised_to(rates, mid) < total ? level_lo : level_hi) = mid;
  }
  for (float& r : rates) r = std::max(r, static_cast<float>(level_lo));
  return rates;
}

std::vector<float> allocation_weights(const std::vector<float>& dilated_need, const std::vector<uint32_t>& paths,
                                      const AdaptiveParams& params) {
  std::vector<float> weights(dilated_need.size());
  for (size_t p = 0; p < weights.size(); ++p) {
    const float need = std::isnan(dilated_need[p]) ? std::numeric_limits<float>::infinity() : dilated_need[p];
    weights[p] = allocation_weight(need, paths[p], params);
  }
  return weights;
}

std::vector<float> clean_shortfall(const std::vector<float>& need, const std::vector<uint32_t>& paths, int width,
                                   int height, const AdaptiveParams& params) {
  std::vector<float> count_needed(need.size());  // x_q = r_q n_q, the count that brings q to t
  for (size_t q = 0; q < need.size(); ++q) {
    const float r = std::isnan(need[q]) ? std::numeric_limits<float>::infinity() : need[q];
    count_needed[q] = r * static_cast<float>(std::max<uint32_t>(paths[q], 1));
  }
  const std::vector<float> predicted = neighbourhood_need(count_needed, width, height, params.dilation_radius);
  std::vector<float> shortfall(need.size());
  for (size_t p = 0; p < need.size(); ++p) {
    const float target = std::max(static_cast<float>(params.min_samples), params.clean_margin * predicted[p]);
    shortfall[p] = std::max(0.0f, target - static_cast<float>(paths[p]));
  }
  return shortfall;
}

std::vector<float> sampling_rates(const std::vector<float>& dilated_need, const std::vector<uint32_t>& paths,
                                  const AdaptiveParams& params) {
  const std::vector<float> weights = allocation_weights(dilated_need, paths, params);
  const double total = static_cast<double>(params.frame_paths) * static_cast<double>(weights.size());
  return water_fill(weights, total, params.floor_rate, std::min(params.max_rate, static_cast<float>(kMaxPathsPerFrame)));
}

std::vector<float> allocation_rates(const std::vector<float>& need, const std::vector<uint32_t>& paths, int width,
                                    int height, const AdaptiveParams& params) {
  if (params.goal == AdaptiveGoal::Error)
    return sampling_rates(neighbourhood_need(need, width, height, params.dilation_radius), paths, params);
  const std::vector<float> weights = clean_shortfall(need, paths, width, height, params);
  const double total = static_cast<double>(params.frame_paths) * static_cast<double>(weights.size());
  return water_fill(weights, total, params.floor_rate, std::min(params.max_rate, static_cast<float>(kMaxPathsPerFrame)));
}

std::vector<uint8_t> select_active(const std::vector<float>& rates, std::vector<float>& credit) {
  credit.resize(rates.size(), 0.0f);
  std::vector<uint8_t> active(rates.size());
  for (size_t p = 0; p < rates.size(); ++p) {
    credit[p] += rates[p];
    const float paths = std::floor(std::min(credit[p], 255.0f));
    active[p] = static_cast<uint8_t>(paths);
    credit[p] -= paths;
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
