// The per-pixel accumulation of a progressive render: running means of the LV, HV and albedo
// buffers, Welford states of the LV and HV luminance, the interleaved replicates' sums, and the
// variance of the pixel mean that the blend and adaptive sampling read from them.
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>
#include <glm/glm.hpp>

namespace pxf {

// Per-pixel accumulations, row-major, top row first.
struct Accumulation {
  int width = 0, height = 0;
  std::vector<glm::vec3> lv_mean;      // mean RGB radiance of LV paths
  std::vector<glm::vec3> hv_mean;      // mean RGB radiance of HV paths
  std::vector<glm::vec3> albedo_mean;  // mean PathSample::albedo (coverage x first non-delta albedo)
  std::vector<double> hv_lum_mean;     // Welford state of HV luminance
  std::vector<double> hv_lum_m2;
  // Welford state of LV luminance: LV is never filtered, so its noise is part of what the viewer
  // sees; adaptive sampling judges the final pixel L_lv + L_u by it (preview/adaptive.h).
  std::vector<double> lv_lum_mean;
  std::vector<double> lv_lum_m2;
  std::vector<uint32_t> samples;       // accepted samples per pixel (NaN/Inf samples dropped)
  // Interleaved replicates (TraceParams::replicates, 1 = none): HV luminance sum and sample count
  // of replicate r of pixel p at [p * replicates + r].
  int replicates = 1;
  std::vector<double> replicate_lum_sum;
  std::vector<uint32_t> replicate_samples;
  // The even half: the samples of even sample index (frame k's path j of a pixel has index
  // k * paths + j, so a pixel's indices are consecutive and its halves differ by at most one
  // sample). Their HV mean and the Welford state of their luminance; the odd half is the rest. The
  // blend decides each half's weight from the other half's variance (docs/method.md section 3.8).
  // Kept only with split_halves (TraceParams::split_halves); empty otherwise.
  bool split_halves = false;
  std::vector<glm::vec3> even_hv_mean;
  std::vector<double> even_lum_mean;
  std::vector<double> even_lum_m2;
  std::vector<uint32_t> even_samples;

  // Var[L_u] of the HV luminance mean; negative (-1) when n < 2 (unknown). Without replicates it is
  // s^2 / n. With replicates (randomized QMC, where s^2 / n overestimates), it is s^2 / n times the
  // QMC gain: the sum over the 3x3 neighbourhood of the replicate estimates divided by the sum of
  // the s^2 / n estimates. Each replicate estimate alone has only K - 1 degrees of freedom; pooling
  // the gain, which varies slowly across the image, keeps the n - 1 of s^2 / n.
  float variance_of_mean(size_t pixel) const;
  std::vector<float> variance_of_mean_image() const;  // variance_of_mean of every pixel, in O(pixels)
  void variance_of_mean_image(float* out, size_t stride) const;  // the same into out[pixel * stride]
  // 4 floats per pixel: rgb hv_mean, a variance_of_mean (-1 where n < 2). The preview uploads this
  // buffer as its HV texture as it is.
  void hv_and_variance_of_mean(float* rgba) const;
  float per_sample_variance_of_mean(size_t pixel) const;  // s^2 / n, -1 when n < 2
  // Var[L_lv] of the LV luminance mean, s^2 / n (no replicate gain); -1 when n < 2.
  float lv_variance_of_mean(size_t pixel) const;
  // K'/(K'-1) sum_r (n_r / n)^2 (m_r - m)^2 over the K' replicates with samples; -1 when K' < 2.
  float replicate_variance_of_mean(size_t pixel) const;
  // The halves of every pixel, for the blend's split decision: 4 floats per pixel in `halves`
  // (rgb the even half's HV mean, a its share of the samples n_even / n, 0 without samples) and 2 in
  // `half_variances`: the variance of the whole pixel mean as each half's samples alone estimate
  // it (s_h^2 / n times the pixel's replicate gain, whole / per_sample_variance_of_mean), even
  // then odd; -1 where that half holds fewer than 2 samples. whole_rgba: hv_and_variance_of_mean's
  // buffer, whose alpha is the whole estimate. Throws pxf::Error without split_halves.
  void hv_halves(const float* whole_rgba, float* halves, float* half_variances) const;
};

// Adds one accepted sample to pixel `pixel`: running means of LV/HV RGB and Welford (double) of
// the HV luminance, running mean of the albedo. The caller has already rejected non-finite samples.
// `sample_index` is the sample's index in the pixel's sequence: its replicate is the index mod
// acc.replicates (for a uniform render, the frame's), its half the index's parity.
void accumulate_sample(Accumulation& acc, size_t pixel, glm::vec3 lv, glm::vec3 hv, uint32_t sample_index = 0,
                       glm::vec3 albedo = glm::vec3(1.0f));
// Sizes and clears every array; the even half's only with `halves`.
void resize_accumulation(Accumulation& acc, int width, int height, int replicates = 1, bool halves = false);

}  // namespace pxf
