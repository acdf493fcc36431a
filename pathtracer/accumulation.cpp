#include "pathtracer/accumulation.h"

#include <algorithm>
#include <limits>
#include <utility>

#include "core/error.h"
#include "pathtracer/sampling.h"

namespace pxf {

void resize_accumulation(Accumulation& acc, int width, int height, int replicates, bool halves) {
  size_t n = static_cast<size_t>(width) * static_cast<size_t>(height);
  acc.width = width;
  acc.height = height;
  acc.lv_mean.assign(n, glm::vec3(0.0f));
  acc.hv_mean.assign(n, glm::vec3(0.0f));
  acc.albedo_mean.assign(n, glm::vec3(0.0f));
  acc.hv_lum_mean.assign(n, 0.0);
  acc.hv_lum_m2.assign(n, 0.0);
  acc.lv_lum_mean.assign(n, 0.0);
  acc.lv_lum_m2.assign(n, 0.0);
  acc.samples.assign(n, 0u);
  acc.replicates = std::max(1, replicates);
  const size_t replicate_slots = acc.replicates > 1 ? n * static_cast<size_t>(acc.replicates) : 0;
  acc.replicate_lum_sum.assign(replicate_slots, 0.0);
  acc.replicate_samples.assign(replicate_slots, 0u);
  acc.split_halves = halves;
  const size_t half_slots = halves ? n : 0;
  acc.even_hv_mean.assign(half_slots, glm::vec3(0.0f));
  acc.even_lum_mean.assign(half_slots, 0.0);
  acc.even_lum_m2.assign(half_slots, 0.0);
  acc.even_samples.assign(half_slots, 0u);
}

namespace {
void add_welford(double& mean, double& m2, uint32_t n, double y) {
  const double delta = y - mean;
  mean += delta / static_cast<double>(n);
  m2 += delta * (y - mean);
}
}  // namespace

void accumulate_sample(Accumulation& acc, size_t pixel, glm::vec3 lv, glm::vec3 hv, uint32_t sample_index,
                       glm::vec3 albedo) {
  uint32_t n = ++acc.samples[pixel];
  float inv_n = 1.0f / static_cast<float>(n);
  acc.lv_mean[pixel] += (lv - acc.lv_mean[pixel]) * inv_n;
  acc.hv_mean[pixel] += (hv - acc.hv_mean[pixel]) * inv_n;
  acc.albedo_mean[pixel] += (albedo - acc.albedo_mean[pixel]) * inv_n;
  const double y = luminance(hv);
  add_welford(acc.hv_lum_mean[pixel], acc.hv_lum_m2[pixel], n, y);
  add_welford(acc.lv_lum_mean[pixel], acc.lv_lum_m2[pixel], n, luminance(lv));
  if (acc.replicates > 1) {
    const uint32_t replicate = sample_index % static_cast<uint32_t>(acc.replicates);
    const size_t slot = pixel * static_cast<size_t>(acc.replicates) + replicate;
    acc.replicate_lum_sum[slot] += y;
    ++acc.replicate_samples[slot];
  }
  if (acc.split_halves && sample_index % 2 == 0) {
    const uint32_t n_even = ++acc.even_samples[pixel];
    acc.even_hv_mean[pixel] += (hv - acc.even_hv_mean[pixel]) * (1.0f / static_cast<float>(n_even));
    add_welford(acc.even_lum_mean[pixel], acc.even_lum_m2[pixel], n_even, y);
  }
}

namespace {
// s^2 / n of a Welford state of n samples; -1 when n < 2.
float welford_variance_of_mean(double m2, uint32_t n) {
  if (n < 2) return -1.0f;
  double var = m2 / static_cast<double>(n - 1) / static_cast<double>(n);
  // Saturate rather than overflow: a very bright but finite input (luminance near the float limit)
  // has a variance beyond float range, and an infinite variance would poison every later pass.
  return static_cast<float>(std::clamp(var, 0.0, static_cast<double>(std::numeric_limits<float>::max())));
}
}  // namespace

float Accumulation::per_sample_variance_of_mean(size_t pixel) const {
  return welford_variance_of_mean(hv_lum_m2[pixel], samples[pixel]);
}

float Accumulation::lv_variance_of_mean(size_t pixel) const {
  return welford_variance_of_mean(lv_lum_m2[pixel], samples[pixel]);
}

float Accumulation::replicate_variance_of_mean(size_t pixel) const {
  if (replicates < 2) return -1.0f;
  const double* sums = &replicate_lum_sum[pixel * static_cast<size_t>(replicates)];
  const uint32_t* counts = &replicate_samples[pixel * static_cast<size_t>(replicates)];
  int used = 0;
  double total = 0, n = 0;
  for (int r = 0; r < replicates; ++r) {
    if (counts[r] == 0) continue;
    ++used;
    total += sums[r];
    n += counts[r];
  }
  if (used < 2) return -1.0f;
  const double mean = total / n;
  double sum = 0;
  for (int r = 0; r < replicates; ++r) {
    if (counts[r] == 0) continue;
    const double weight = counts[r] / n, d = sums[r] / counts[r] - mean;
    sum += weight * weight * d * d;
  }
  return static_cast<float>(sum * used / (used - 1));
}

namespace {

// s^2 / n of `pixel` times the QMC gain pooled over its 3x3 neighbourhood; estimates(q) gives the
// replicate and the per-sample estimate of pixel q (-1: unknown). One formula for the per-pixel
// query and the whole image, so both give the same bits.
template <class Estimates>
float pooled_gain_variance_of_mean(const Accumulation& acc, size_t pixel, const Estimates& estimates) {
  const float own = estimates(pixel).second;
  if (acc.replicates < 2 || own <= 0.0f) return own;
  const int x = static_cast<int>(pixel % static_cast<size_t>(acc.width));
  const int y = static_cast<int>(pixel / static_cast<size_t>(acc.width));
  double replicate_sum = 0, per_sample_sum = 0;
  for (int ny = std::max(0, y - 1); ny <= std::min(acc.height - 1, y + 1); ++ny)
    for (int nx = std::max(0, x - 1); nx <= std::min(acc.width - 1, x + 1); ++nx) {
      const auto [r, v] = estimates(static_cast<size_t>(ny) * static_cast<size_t>(acc.width) + static_cast<size_t>(nx));
      if (r < 0.0f || v < 0.0f) continue;
      replicate_sum += r;
      per_sample_sum += v;
    }
  if (!(per_sample_sum > 0.0)) return own;
  return static_cast<float>(own * (replicate_sum / per_sample_sum));
}

}  // namespace

float Accumulation::variance_of_mean(size_t pixel) const {
  return pooled_gain_variance_of_mean(*this, pixel, [this](size_t q) {
    return std::make_pair(replicate_variance_of_mean(q), per_sample_variance_of_mean(q));
  });
}

void Accumulation::variance_of_mean_image(float* out, size_t stride) const {
  const size_t n = samples.size();
  std::vector<std::pair<float, float>> estimates(n);
  for (size_t q = 0; q < n; ++q) estimates[q] = {replicate_variance_of_mean(q), per_sample_variance_of_mean(q)};
  for (size_t p = 0; p < n; ++p)
    out[p * stride] = pooled_gain_variance_of_mean(*this, p, [&estimates](size_t q) { return estimates[q]; });
}

std::vector<float> Accumulation::variance_of_mean_image() const {
  std::vector<float> out(samples.size());
  variance_of_mean_image(out.data(), 1);
  return out;
}

void Accumulation::hv_and_variance_of_mean(float* rgba) const {
  for (size_t p = 0; p < hv_mean.size(); ++p) {
    rgba[4 * p + 0] = hv_mean[p].x;
    rgba[4 * p + 1] = hv_mean[p].y;
    rgba[4 * p + 2] = hv_mean[p].z;
  }
  variance_of_mean_image(rgba + 3, 4);
}

void Accumulation::hv_halves(const float* whole_rgba, float* halves, float* half_variances) const {
  if (!split_halves) throw Error("the accumulation keeps no halves (TraceParams::split_halves off)");
  for (size_t p = 0; p < samples.size(); ++p) {
    const uint32_t n = samples[p], n_even = even_samples[p], n_odd = n - n_even;
    halves[4 * p + 0] = even_hv_mean[p].x;
    halves[4 * p + 1] = even_hv_mean[p].y;
    halves[4 * p + 2] = even_hv_mean[p].z;
    halves[4 * p + 3] = n > 0 ? static_cast<float>(static_cast<double>(n_even) / n) : 0.0f;
    // The odd half's Welford state: Chan's combination of the halves into the whole, solved for it.
    // What is left of the subtraction below kOddM2Resolution of the whole M2 is its rounding: odd
    // samples that were all equal (all 0 beside one bright even sample) come out as a few ulps of
    // either sign, which would read as a known, tiny variance in one render and as 0 (no evidence,
    // shared::zero_variance_u) in the same samples merged from shards.
    constexpr double kOddM2Resolution = 1e-9;
    double odd_m2 = 0;
    if (n_odd > 0 && n_even > 0) {
      const double odd_mean = (hv_lum_mean[p] * n - even_lum_mean[p] * n_even) / n_odd;
      const double delta = odd_mean - even_lum_mean[p];
      odd_m2 = hv_lum_m2[p] - even_lum_m2[p] - delta * delta * n_even * n_odd / n;
      if (!(odd_m2 > kOddM2Resolution * hv_lum_m2[p])) odd_m2 = 0.0;
    } else if (n_odd > 0) {
      odd_m2 = hv_lum_m2[p];
    }
    // The replicate gain of the whole estimate carries over to each half's.
    const float per_sample = per_sample_variance_of_mean(p);
    const float whole = whole_rgba[4 * p + 3];
    const double gain = per_sample > 0.0f && whole > 0.0f ? static_cast<double>(whole) / per_sample : 1.0;
    auto estimate = [&](double m2, uint32_t count) {
      if (count < 2) return -1.0f;
      const double var = m2 / (count - 1) / n * gain;
      return static_cast<float>(std::clamp(var, 0.0, static_cast<double>(std::numeric_limits<float>::max())));
    };
    half_variances[2 * p + 0] = estimate(even_lum_m2[p], n_even);
    half_variances[2 * p + 1] = estimate(odd_m2, n_odd);
  }
}

}  // namespace pxf
