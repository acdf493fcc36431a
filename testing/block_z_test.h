// Two renders of the same image agree: a Z-test of their 4x4 (or any size) blocks' mean luminance,
// block by block and over the whole image, from the accumulations' Welford states. Header-only: its
// users link the path tracer, which pxf_testing does not.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "pathtracer/accumulation.h"
#include "pathtracer/sampling.h"

namespace pxf {

// The mean luminance of each block and the variance of that mean (Var[LV + HV] <= (sd_LV + sd_HV)^2:
// no covariance is kept).
struct Blocks {
  std::vector<double> mean, variance;
};
inline Blocks blocks_of(const Accumulation& acc, int block) {
  Blocks b;
  const int bx = acc.width / block, by = acc.height / block;
  b.mean.assign(static_cast<size_t>(bx * by), 0.0);
  b.variance.assign(b.mean.size(), 0.0);
  const double pixels = block * block;
  for (int y = 0; y < by * block; ++y)
    for (int x = 0; x < bx * block; ++x) {
      const size_t p = static_cast<size_t>(y) * acc.width + x, k = static_cast<size_t>((y / block) * bx + x / block);
      const double n = acc.samples[p];
      const double sd = std::sqrt(acc.lv_lum_m2[p] / (n - 1)) + std::sqrt(acc.hv_lum_m2[p] / (n - 1));
      b.mean[k] += luminance(acc.lv_mean[p] + acc.hv_mean[p]) / pixels;
      b.variance[k] += sd * sd / n / (pixels * pixels);
    }
  return b;
}

struct BlockComparison {
  double worst_z = 0.0;  // the largest |z| of a block
  int beyond3 = 0;       // blocks with |z| > 3
  double image_z = 0.0;  // of the image's mean
  double mean_a = 0.0, mean_b = 0.0;
  double variance_a = 0.0, variance_b = 0.0;  // the blocks' summed variances: each render's noise
};
inline BlockComparison compare_blocks(const Accumulation& a, const Accumulation& b, int block, const char* what) {
  const Blocks ba = blocks_of(a, block), bb = blocks_of(b, block);
  BlockComparison c;
  double sum_a = 0, sum_b = 0;
  for (size_t k = 0; k < ba.mean.size(); ++k) {
    const double z = (ba.mean[k] - bb.mean[k]) / std::sqrt(ba.variance[k] + bb.variance[k]);
    c.worst_z = std::max(c.worst_z, std::abs(z));
    c.beyond3 += std::abs(z) > 3.0;
    sum_a += ba.mean[k];
    sum_b += bb.mean[k];
    c.variance_a += ba.variance[k];
    c.variance_b += bb.variance[k];
  }
  c.image_z = (sum_a - sum_b) / std::sqrt(c.variance_a + c.variance_b);
  c.mean_a = sum_a / static_cast<double>(ba.mean.size());
  c.mean_b = sum_b / static_cast<double>(bb.mean.size());
  std::printf("%s: %zu blocks, worst |z| %.2f, %d beyond 3, image z %.2f (means %.5f, %.5f; variances %.3g, %.3g)\n",
              what, ba.mean.size(), c.worst_z, c.beyond3, c.image_z, c.mean_a, c.mean_b, c.variance_a, c.variance_b);
  return c;
}

}  // namespace pxf
