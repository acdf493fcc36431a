// The sheen lobe's pieces (sheen.h): the Charlie distribution is normalized, the checked-in albedo
// table is its generator's output, and the lookup interpolates it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <utility>

#include "pathtracer/sheen.h"

namespace pxf {
namespace {

constexpr int kGeneratorQuadrature = 1024;  // make_albedo_table sheen's

TEST(Sheen, CharlieDistributionIsNormalized) {
  for (float alpha : {kMinSheenAlpha, 0.25f, 1.0f}) {
    double sum = 0;
    const int n = 200000;
    for (int i = 0; i < n; ++i) {  // integral of D(h) cos(theta_h) over the hemisphere, midpoint in cos theta
      const double z = (i + 0.5) / n;
      sum += charlie_d(static_cast<float>(z), alpha) * z * (1.0 / n) * 2.0 * M_PI;
    }
    EXPECT_NEAR(sum, 1.0, 2e-3) << "alpha " << alpha;
  }
}

TEST(Sheen, TableIsTheGeneratorsOutput) {
  for (auto [i, j] : {std::pair{0, 31}, {8, 3}, {20, 17}, {31, 0}, {31, 31}}) {
    const float r = sheen_table_roughness(i), s = static_cast<float>(j) / (kSheenAlbedoSize - 1);
    const float fresh = sheen_albedo_quadrature(s * s, sheen_alpha(r), kGeneratorQuadrature);
    EXPECT_NEAR(sheen_albedo_table_entry(i, j), fresh, 2e-6f) << i << ", " << j;
  }
}

TEST(Sheen, LookupInterpolatesTheAlbedo) {
  // The albedo exceeds 1 only within 6 degrees of grazing below sheen roughness 0.2 (the Bsdf
  // scales the lobe down there); elsewhere it is below 1.
  EXPECT_LT(sheen_albedo(0.1f, sheen_alpha(0.1f)), 1.0f);
  EXPECT_LT(sheen_albedo(0.004f, sheen_alpha(0.2f)), 1.0f);
  // Within 0.005 above sheen roughness 0.2 and 6 degrees from grazing, where the albedo is smooth;
  // within 0.025 at the steep grazing and low-roughness end.
  float worst = 0.0f, worst_steep = 0.0f;
  for (int i = 0; i + 1 < kSheenAlbedoSize; i += 3)
    for (int j = 0; j + 1 < kSheenAlbedoSize; j += 3) {
      const float r = 0.5f * (sheen_table_roughness(i) + sheen_table_roughness(i + 1)), s = (j + 0.5f) / (kSheenAlbedoSize - 1);
      const float exact = sheen_albedo_quadrature(s * s, sheen_alpha(r), 128);
      const float error = std::abs(sheen_albedo(s * s, sheen_alpha(r)) - exact);
      float& bucket = r > 0.2f && s * s > 0.1f ? worst : worst_steep;
      bucket = std::max(bucket, error);
    }
  std::printf("largest absolute interpolation error of E_sheen: %.5f (steep end %.5f)\n", worst, worst_steep);
  EXPECT_LT(worst, 5e-3f);
  EXPECT_LT(worst_steep, 2.5e-2f);
}

}  // namespace
}  // namespace pxf
