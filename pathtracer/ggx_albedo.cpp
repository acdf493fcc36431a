#include "pathtracer/ggx_albedo.h"

#include <algorithm>
#include <cmath>

#include "pathtracer/bsdf.h"

namespace pxf {
namespace {

constexpr GgxAlbedo kTable[kGgxAlbedoSize][kGgxAlbedoSize] = {
#include "pathtracer/ggx_albedo_table.inc"
};

}  // namespace

GgxAlbedo ggx_albedo_quadrature(float cos_o, float alpha, int n) {
  cos_o = std::max(cos_o, kGgxAlbedoMinCos);
  const glm::vec3 wo(std::sqrt(std::max(0.0f, 1.0f - cos_o * cos_o)), 0.0f, cos_o);
  const double lambda_o = ggx_lambda(wo, alpha);
  double total = 0.0, schlick = 0.0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const glm::vec2 u((i + 0.5f) / n, (j + 0.5f) / n);
      const glm::vec3 h = ggx_sample_vndf(wo, alpha, u);
      const glm::vec3 wi = glm::reflect(-wo, h);
      if (wi.z <= 0.0f) continue;
      const double g2_over_g1 = (1.0 + lambda_o) / (1.0 + lambda_o + ggx_lambda(wi, alpha));
      const double w = std::pow(1.0 - std::clamp(static_cast<double>(glm::dot(wo, h)), 0.0, 1.0), 5.0);
      total += g2_over_g1;
      schlick += g2_over_g1 * w;
    }
  const double cells = static_cast<double>(n) * n;
  return {static_cast<float>(total / cells), static_cast<float>(schlick / cells)};
}

const GgxAlbedo& ggx_albedo_table_entry(int roughness_index, int cos_index) {
  return kTable[roughness_index][cos_index];
}

GgxAlbedo ggx_albedo(float cos_o, float alpha) {
  constexpr float last = kGgxAlbedoSize - 1;
  const float x = std::sqrt(std::clamp(cos_o, 0.0f, 1.0f)) * last;
  const float y = std::clamp(std::sqrt(std::max(alpha, 0.0f)), 0.0f, 1.0f) * last;
  const int x0 = std::min(static_cast<int>(x), kGgxAlbedoSize - 2), y0 = std::min(static_cast<int>(y), kGgxAlbedoSize - 2);
  const float fx = x - x0, fy = y - y0;
  auto mix = [fx, fy](float a, float b, float c, float d) {  // (x0,y0) (x1,y0) (x0,y1) (x1,y1)
    return (a * (1.0f - fx) + b * fx) * (1.0f - fy) + (c * (1.0f - fx) + d * fx) * fy;
  };
  const GgxAlbedo& a = kTable[y0][x0];
  const GgxAlbedo& b = kTable[y0][x0 + 1];
  const GgxAlbedo& c = kTable[y0 + 1][x0];
  const GgxAlbedo& d = kTable[y0 + 1][x0 + 1];
  return {mix(a.total, b.total, c.total, d.total), mix(a.schlick, b.schlick, c.schlick, d.schlick)};
}

}  // namespace pxf
