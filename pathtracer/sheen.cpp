#include "pathtracer/sheen.h"

#include <algorithm>
#include <cmath>

namespace pxf {
namespace {

constexpr float kTable[kSheenAlbedoSize][kSheenAlbedoSize] = {
#include "pathtracer/sheen_albedo_table.inc"
};

constexpr double kPiD = 3.14159265358979323846;

}  // namespace

float charlie_d(float cos_h, float alpha) {
  const float inv_alpha = 1.0f / alpha;
  const float sin2 = std::max(0.0f, 1.0f - cos_h * cos_h);
  return (2.0f + inv_alpha) * std::pow(sin2, 0.5f * inv_alpha) / (2.0f * static_cast<float>(kPiD));
}

namespace {

// Estevez and Kulla's fit of the Charlie distribution's Lambda: the exponent at cos theta = x, its
// five parameters blended between their alpha = 0 and alpha = 1 fits by (1 - alpha)^2.
float sheen_lambda_exponent(float x, float alpha) {
  const float t = (1.0f - alpha) * (1.0f - alpha);
  auto mix = [t](float at_1, float at_0) { return at_1 + (at_0 - at_1) * t; };
  const float a = mix(21.5473f, 25.3245f), b = mix(3.82987f, 3.32435f), c = mix(0.19823f, 0.16801f);
  const float d = mix(-1.97760f, -1.27393f), e = mix(-4.32054f, -4.85967f);
  return a / (1.0f + b * std::pow(x, c)) + d * x + e;
}

float sheen_lambda(float cos_theta, float alpha) {
  return cos_theta < 0.5f ? std::exp(sheen_lambda_exponent(cos_theta, alpha))
                          : std::exp(2.0f * sheen_lambda_exponent(0.5f, alpha) - sheen_lambda_exponent(1.0f - cos_theta, alpha));
}

}  // namespace

float sheen_visibility(float cos_o, float cos_i, float alpha) {
  const float denom = (1.0f + sheen_lambda(cos_o, alpha) + sheen_lambda(cos_i, alpha)) * 4.0f * cos_o * cos_i;
  return denom > 0.0f ? std::min(1.0f / denom, 1.0f) : 0.0f;
}

float sheen_albedo_quadrature(float cos_o, float alpha, int n) {
  const double mu = std::max(cos_o, 1e-4f);
  const double st_o = std::sqrt(1.0 - mu * mu);
  const int n_theta = n, n_phi = n / 2;
  double sum = 0.0;
  for (int i = 0; i < n_theta; ++i) {
    const double ct = (i + 0.5) / n_theta, st = std::sqrt(1.0 - ct * ct);
    for (int j = 0; j < n_phi; ++j) {
      const double phi = kPiD * (j + 0.5) / n_phi;
      // h = normalize(wo + wi), wo = (st_o, 0, mu): only its z over its length is needed.
      const double hx = st_o + st * std::cos(phi), hy = st * std::sin(phi), hz = mu + ct;
      const double cos_h = hz / std::sqrt(hx * hx + hy * hy + hz * hz);
      sum += charlie_d(static_cast<float>(cos_h), alpha) * sheen_visibility(static_cast<float>(mu), static_cast<float>(ct), alpha) * ct;
    }
  }
  return static_cast<float>(sum * (1.0 / n_theta) * (2.0 * kPiD / n_phi));
}

float sheen_albedo_table_entry(int roughness_index, int cos_index) { return kTable[roughness_index][cos_index]; }

float sheen_table_roughness(int row) {
  const float lowest = std::sqrt(kMinSheenAlpha);
  return lowest + (1.0f - lowest) * static_cast<float>(row) / (kSheenAlbedoSize - 1);
}

float sheen_albedo(float cos_o, float alpha) {
  constexpr float last = kSheenAlbedoSize - 1;
  const float x = std::sqrt(std::clamp(cos_o, 0.0f, 1.0f)) * last;
  const float lowest = std::sqrt(kMinSheenAlpha);
  const float y = std::clamp((std::sqrt(std::max(alpha, 0.0f)) - lowest) / (1.0f - lowest), 0.0f, 1.0f) * last;
  const int x0 = std::min(static_cast<int>(x), kSheenAlbedoSize - 2), y0 = std::min(static_cast<int>(y), kSheenAlbedoSize - 2);
  const float fx = x - x0, fy = y - y0;
  const float low = kTable[y0][x0] * (1.0f - fx) + kTable[y0][x0 + 1] * fx;
  const float high = kTable[y0 + 1][x0] * (1.0f - fx) + kTable[y0 + 1][x0 + 1] * fx;
  return low * (1.0f - fy) + high * fy;
}

}  // namespace pxf
