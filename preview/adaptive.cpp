#include "preview/adaptive.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>

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

namespace {

// For each pixel, `reduce` of the values of the OTHER pixels of the (2 radius + 1)^2 box around it.
template <typename Reduce>
std::vector<float> over_the_others(const std::vector<float>& values, int width, int height, int radius,
                                   Reduce reduce) {
  std::vector<float> out(values.size());
  std::vector<float> others;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      others.clear();
      for (int qy = std::max(0, y - radius); qy <= std::min(height - 1, y + radius); ++qy)
        for (int qx = std::max(0, x - radius); qx <= std::min(width - 1, x + radius); ++qx)
          if (qx != x || qy != y) others.push_back(values[static_cast<size_t>(qy) * width + qx]);
      out[static_cast<size_t>(y) * width + x] = reduce(others);
    }
  return out;
}

}  // namespace

std::vector<float> neighbourhood_median(const std::vector<float>& values, int width, int height, int radius) {
  return over_the_others(values, width, height, radius, [](std::vector<float>& others) {
    if (others.empty()) return 0.0f;
    const auto middle = others.begin() + static_cast<std::ptrdiff_t>(others.size() / 2);
    std::nth_element(others.begin(), middle, others.end());
    return *middle;
  });
}

std::vector<float> neighbourhood_need(const std::vector<float>& need, int width, int height, int radius) {
  return over_the_others(need, width, height, radius, [](const std::vector<float>& others) {
    float m = 0.0f;
    for (float v : others) m = std::max(m, v);
    return m;
  });
}

namespace {

// w_p of goal Error (preview/adaptive.h): s_p = sqrt(r_p n_p), the per-path relative deviation over
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

// Paths the rates cannot place go to every pixel alike: the floor rises by bisection until the
// rates add up to `total` (or all are at max_rate).
void raise_floor(std::vector<float>& rates, double total, float floor_rate, float max_rate) {
  double level_lo = floor_rate, level_hi = max_rate;
  if (sum_raised_to(rates, max_rate) <= total) level_lo = max_rate;  // a budget past every cap
  for (int i = 0; i < 100 && level_hi - level_lo > 1e-7 * level_hi; ++i) {
    const double mid = 0.5 * (level_lo + level_hi);
    (sum_raised_to(rates, mid) < total ? level_lo : level_hi) = mid;
  }
  for (float& r : rates) r = std::max(r, static_cast<float>(level_lo));
}

// x_q = r_q n_q, the count that brings pixel q to its threshold (+inf: an unknown variance).
std::vector<float> counts_needed(const std::vector<float>& need, const std::vector<uint32_t>& paths) {
  std::vector<float> x(need.size());
  for (size_t q = 0; q < need.size(); ++q) {
    const float r = std::isnan(need[q]) ? std::numeric_limits<float>::infinity() : need[q];
    x[q] = r * static_cast<float>(std::max<uint32_t>(paths[q], 1));
  }
  return x;
}

// The paths a pixel lacks to `target`, which is at least the minimum count.
float lack_to(float target, uint32_t paths, const AdaptiveParams& params) {
  return std::max(0.0f, std::max(static_cast<float>(params.min_samples), target) - static_cast<float>(paths));
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
  // The weights cannot take the paths (every weighted pixel at max_rate).
  raise_floor(rates, total, floor_rate, max_rate);
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

std::vector<CleanLack> clean_lacks(const std::vector<float>& need, const std::vector<uint32_t>& paths, int width,
                                   int height, const AdaptiveParams& params) {
  const std::vector<float> x = counts_needed(need, paths);
  const std::vector<float> largest = neighbourhood_need(x, width, height, params.dilation_radius);
  const std::vector<float> typical = neighbourhood_median(x, width, height, params.dilation_radius);
  std::vector<CleanLack> lacks(need.size());
  for (size_t p = 0; p < need.size(); ++p)
    lacks[p] = {lack_to(typical[p], paths[p], params), lack_to(params.clean_margin * largest[p], paths[p], params)};
  return lacks;
}

std::vector<float> shortest_lack_first(const std::vector<CleanLack>& lacks, double total, float floor_rate,
                                       float max_rate, double horizon) {
  // A share of a pixel's lack: stage 0 what it lacks of its typical count, stage 1 what it lacks of
  // its full count beyond that. Served by stage, then by the lack that orders it, then by pixel.
  struct Share {
    int stage;
    float order, paths;
    uint32_t pixel;
  };
  std::vector<Share> shares;
  for (uint32_t p = 0; p < lacks.size(); ++p) {
    if (lacks[p].typical > 0.0f) shares.push_back({0, lacks[p].typical, lacks[p].typical, p});
    if (lacks[p].full > lacks[p].typical) shares.push_back({1, lacks[p].full, lacks[p].full - lacks[p].typical, p});
  }
  std::sort(shares.begin(), shares.end(), [](const Share& a, const Share& b) {
    return std::tie(a.stage, a.order, a.pixel) < std::tie(b.stage, b.order, b.pixel);
  });
  // Each pixel's rate is the floor plus what its shares were given, at most max_rate.
  std::vector<float> rates(lacks.size(), floor_rate);
  double left = total - static_cast<double>(floor_rate) * static_cast<double>(lacks.size());
  for (const Share& share : shares) {
    if (!(left > 0.0)) break;
    float& rate = rates[share.pixel];
    const double given = std::min({share.paths / horizon, double{max_rate} - rate, left});
    if (!(given > 0.0)) continue;
    rate = static_cast<float>(rate + given);
    left -= given;
  }
  if (left > 0.0) raise_floor(rates, total, floor_rate, max_rate);
  return rates;
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
  const double total = static_cast<double>(params.frame_paths) * static_cast<double>(need.size());
  // The rates hold until the frames grow by 1 / replan_divisor (a frame adds frame_paths per pixel).
  const double frames = sample_counts(paths).mean / params.frame_paths;
  const double horizon = std::max(1.0, frames / params.replan_divisor);
  return shortest_lack_first(clean_lacks(need, paths, width, height, params), total, params.floor_rate,
                             std::min(params.max_rate, static_cast<float>(kMaxPathsPerFrame)), horizon);
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
