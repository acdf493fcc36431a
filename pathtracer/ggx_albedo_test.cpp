// The tabulated single-scattering GGX albedo (ggx_albedo.h): the checked-in table is its generator's
// output, the generator's quadrature agrees with an independent one, and the lookup interpolates it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "pathtracer/bsdf.h"
#include "pathtracer/ggx_albedo.h"

namespace pxf {
namespace {

constexpr int kGeneratorQuadrature = 1024;  // make_albedo_table's

float grid_cos(int j) { return albedo_grid_cos(j, kGgxAlbedoSize); }
float grid_alpha(int i) { return albedo_grid_alpha(i, kGgxAlbedoSize, kMinAlpha); }

TEST(GgxAlbedo, TableIsTheGeneratorsOutput) {
  // A stale table (the BSDF's G2 or the grid changed without regenerating) fails here.
  for (auto [i, j] : {std::pair{0, 0}, {5, 31}, {15, 3}, {31, 17}}) {
    const GgxAlbedo fresh = ggx_albedo_quadrature(grid_cos(j), grid_alpha(i), kGeneratorQuadrature);
    const GgxAlbedo& stored = ggx_albedo_table_entry(i, j);
    EXPECT_NEAR(stored.total, fresh.total, 2e-6f) << i << ", " << j;
    EXPECT_NEAR(stored.schlick, fresh.schlick, 2e-6f) << i << ", " << j;
  }
}

// The albedo written out as the integral over the hemisphere of wi (cos theta x phi midpoint grid),
// height-correlated Smith G2, without the sampling routine the generator uses.
GgxAlbedo hemisphere_quadrature(double mu, double alpha) {
  const double pi = 3.14159265358979323846;
  auto lambda = [alpha](double z) { return 0.5 * (-1.0 + std::sqrt(1.0 + alpha * alpha * (1.0 - z * z) / (z * z))); };
  const glm::dvec3 wo(std::sqrt(1.0 - mu * mu), 0.0, mu);
  const int n_theta = 400, n_phi = 200;  // phi over [0, pi], doubled by symmetry
  double total = 0, schlick = 0;
  for (int i = 0; i < n_theta; ++i) {
    const double ct = (i + 0.5) / n_theta, st = std::sqrt(1.0 - ct * ct);
    for (int j = 0; j < n_phi; ++j) {
      const double phi = pi * (j + 0.5) / n_phi;
      const glm::dvec3 wi(st * std::cos(phi), st * std::sin(phi), ct);
      const glm::dvec3 h = glm::normalize(wo + wi);
      const double a2 = alpha * alpha, t = h.z * h.z * (a2 - 1.0) + 1.0;
      const double f = a2 / (pi * t * t) / (1.0 + lambda(mu) + lambda(ct)) / (4.0 * mu);
      total += f;
      schlick += f * std::pow(1.0 - glm::dot(wo, h), 5.0);
    }
  }
  const double cell = (1.0 / n_theta) * (2.0 * pi / n_phi);
  return {static_cast<float>(total * cell), static_cast<float>(schlick * cell)};
}

TEST(GgxAlbedo, GeneratorAgreesWithHemisphereQuadrature) {
  for (double alpha : {0.25, 0.49, 1.0})
    for (double mu : {1.0, 0.6, 0.25}) {
      const GgxAlbedo a = ggx_albedo_quadrature(static_cast<float>(mu), static_cast<float>(alpha), 256);
      const GgxAlbedo b = hemisphere_quadrature(mu, alpha);
      EXPECT_NEAR(a.total, b.total, 2e-3f) << "alpha " << alpha << " mu " << mu;
      EXPECT_NEAR(a.schlick, b.schlick, 1e-3f) << "alpha " << alpha << " mu " << mu;
    }
  // The figure docs/materials.md quotes: a white metal at roughness 0.5 keeps 91.6 % at normal incidence.
  EXPECT_NEAR(ggx_albedo(1.0f, 0.25f).total, 0.916f, 0.002f);
}

TEST(GgxAlbedo, LookupBetweenGridPointsIsWithinAFewTenthsOfAPercent) {
  // Midway between grid points, where bilinear interpolation errs most, against the quadrature:
  // within 0.3 % up to 87 degrees from the normal; above, at roughness below 0.25 where the albedo
  // dips and recovers within a few degrees of grazing, within 2 %.
  float worst = 0.0f, worst_grazing = 0.0f;
  for (int i = 0; i + 1 < kGgxAlbedoSize; i += 3)
    for (int j = 0; j + 1 < kGgxAlbedoSize; j += 2) {
      const float r = (i + 0.5f) / (kGgxAlbedoSize - 1), s = (j + 0.5f) / (kGgxAlbedoSize - 1);
      const float alpha = std::max(r * r, kMinAlpha), mu = s * s;
      const float exact = ggx_albedo_quadrature(mu, alpha, 128).total;
      const float error = std::abs(ggx_albedo(mu, alpha).total - exact) / exact;
      (mu > 0.05f ? worst : worst_grazing) = std::max(mu > 0.05f ? worst : worst_grazing, error);
    }
  std::printf("largest relative interpolation error of E: %.5f (within 3 degrees of grazing %.5f)\n", worst, worst_grazing);
  EXPECT_LT(worst, 3e-3f);
  EXPECT_LT(worst_grazing, 2e-2f);
}

}  // namespace
}  // namespace pxf
