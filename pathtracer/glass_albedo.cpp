#include "pathtracer/glass_albedo.h"

#include <algorithm>
#include <cmath>

#include "pathtracer/bsdf.h"
#include "pathtracer/ggx_albedo.h"  // kGgxAlbedoMinCos

namespace pxf {
namespace {

constexpr int kRows = 2 * kGlassAlbedoIorSize * kGlassAlbedoRoughnessSize;  // (side, ior, roughness)
constexpr int kLastCos = kGlassAlbedoCosSize - 1;

constexpr GlassAlbedo kTable[kRows][kGlassAlbedoCosSize] = {
#include "pathtracer/glass_albedo_table.inc"
};

constexpr int row_of(int side, int ior_index, int roughness_index) {
  return (side * kGlassAlbedoIorSize + ior_index) * kGlassAlbedoRoughnessSize + roughness_index;
}

// The loss 1 - E of a row, linear in s = sqrt(cos) from point j to j + 1, is A + B s there; its
// integral against 2 mu dmu = 4 s^3 ds from s0 to s is A (s^4 - s0^4) + 4/5 B (s^5 - s0^5).
struct LossSegment {
  double a = 0.0, b = 0.0, s0 = 0.0, s1 = 0.0;
  LossSegment(const GlassAlbedo* row, int j) : s0(static_cast<double>(j) / kLastCos), s1(static_cast<double>(j + 1) / kLastCos) {
    const double e0 = 1.0 - row[j].total, e1 = 1.0 - row[j + 1].total;
    b = (e1 - e0) * kLastCos;
    a = e0 - b * s0;
  }
  double integral(double s) const {
    return a * (s * s * s * s - s0 * s0 * s0 * s0) + 0.8 * b * (s * s * s * s * s - s0 * s0 * s0 * s0 * s0);
  }
  double density(double s) const { return (a + b * s) * 4.0 * s * s * s; }
  // The s in [s0, s1] where integral(s) = target (0 <= target <= integral(s1)): Newton's steps,
  // bisection where a step would leave the bracket. The integral is increasing (the loss is >= 0).
  double solve(double target) const {
    double lo = s0, hi = s1, s = 0.5 * (s0 + s1);
    for (int iteration = 0; iteration < 40; ++iteration) {
      const double value = integral(s) - target;
      (value > 0.0 ? hi : lo) = s;
      const double slope = density(s);
      double next = slope > 0.0 ? s - value / slope : 0.5 * (lo + hi);
      if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
      if (std::abs(next - s) < 1e-10) return next;
      s = next;
    }
    return s;
  }
};

// What the lookups derive from the table once: per row, the loss accumulated up to each grid point
// (the last is 1 - E_avg); per side and ior point, the smooth interface's average Fresnel.
struct Derived {
  float cumulative_loss[kRows][kGlassAlbedoCosSize];
  float fresnel_average[2][kGlassAlbedoIorSize];
};

Derived derive() {
  Derived d{};
  for (int r = 0; r < kRows; ++r) {
    double sum = 0.0;
    d.cumulative_loss[r][0] = 0.0f;
    for (int j = 0; j < kLastCos; ++j) {
      const LossSegment segment(kTable[r], j);
      sum += segment.integral(segment.s1);
      d.cumulative_loss[r][j + 1] = static_cast<float>(sum);
    }
  }
  constexpr int kPoints = 8192;  // midpoint rule in mu: F is smooth but at the critical angle
  for (int side = 0; side < 2; ++side)
    for (int k = 0; k < kGlassAlbedoIorSize; ++k) {
      const float ior = glass_table_ior(k), eta = side == 0 ? ior : 1.0f / ior;
      double sum = 0.0;
      for (int p = 0; p < kPoints; ++p) {
        const double mu = (p + 0.5) / kPoints;
        sum += 2.0 * mu * fresnel_dielectric(static_cast<float>(mu), eta);
      }
      d.fresnel_average[side][k] = static_cast<float>(sum / kPoints);
    }
  return d;
}

const Derived& derived() {
  static const Derived d = derive();
  return d;
}

}  // namespace

float glass_table_ior(int ior_index) {
  const float x = ior_index == 0 ? kGlassAlbedoFirstX : static_cast<float>(ior_index) * kGlassAlbedoIorStep;
  return (1.0f + x) / (1.0f - x);
}

GlassAlbedo glass_albedo_quadrature(float cos_o, float alpha, float eta, int n) {
  cos_o = std::max(cos_o, kGgxAlbedoMinCos);
  const glm::vec3 wo(std::sqrt(std::max(0.0f, 1.0f - cos_o * cos_o)), 0.0f, cos_o);
  const double lambda_o = ggx_lambda(wo, alpha);
  auto g2_over_g1 = [&](glm::vec3 wi) { return (1.0 + lambda_o) / (1.0 + lambda_o + ggx_lambda(wi, alpha)); };
  double reflected = 0.0, transmitted = 0.0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const glm::vec2 u((i + 0.5f) / n, (j + 0.5f) / n);
      const glm::vec3 h = ggx_sample_vndf(wo, alpha, u);
      const float cos_oh = glm::dot(wo, h);
      if (!(cos_oh > 0.0f)) continue;
      const double fresnel = fresnel_dielectric(cos_oh, eta);
      const glm::vec3 wr = glm::reflect(-wo, h);
      if (wr.z > 0.0f) reflected += fresnel * g2_over_g1(wr);
      const float sin2_t = (1.0f - cos_oh * cos_oh) / (eta * eta);
      if (sin2_t >= 1.0f) continue;  // total internal reflection
      const glm::vec3 wt = glm::normalize(-wo / eta + (cos_oh / eta - std::sqrt(1.0f - sin2_t)) * h);
      if (wt.z < 0.0f) transmitted += (1.0 - fresnel) * g2_over_g1(wt);
    }
  const double cells = static_cast<double>(n) * n;
  return {static_cast<float>((reflected + transmitted) / cells), static_cast<float>(reflected / cells)};
}

const GlassAlbedo& glass_albedo_table_entry(int side, int ior_index, int roughness_index, int cos_index) {
  return kTable[row_of(side, ior_index, roughness_index)][cos_index];
}

GlassAlbedoLookup::GlassAlbedoLookup(float alpha, float ior) {
  constexpr float last_r = kGlassAlbedoRoughnessSize - 1, last_k = kGlassAlbedoIorSize - 1;
  const float r = std::clamp(std::sqrt(std::max(alpha, 0.0f)), 0.0f, 1.0f) * last_r;
  // The grid coordinate of x = (ior - 1) / (ior + 1): its first interval is shorter than the rest.
  const float x = (ior - 1.0f) / (ior + 1.0f);
  const float k = std::clamp(x < kGlassAlbedoIorStep ? (x - kGlassAlbedoFirstX) / (kGlassAlbedoIorStep - kGlassAlbedoFirstX)
                                                     : x / kGlassAlbedoIorStep,
                             0.0f, last_k);
  roughness_index_ = std::min(static_cast<int>(r), kGlassAlbedoRoughnessSize - 2);
  ior_index_ = std::min(static_cast<int>(k), kGlassAlbedoIorSize - 2);
  roughness_weight_ = r - roughness_index_;
  ior_weight_ = k - ior_index_;
}

GlassAlbedo GlassAlbedoLookup::at(int side, float cos_theta) const {
  const float x = std::sqrt(std::clamp(cos_theta, 0.0f, 1.0f)) * kLastCos;
  const int j = std::min(static_cast<int>(x), kLastCos - 1);
  const float fx = x - j;
  GlassAlbedo sum{0.0f, 0.0f};
  for (int corner = 0; corner < 4; ++corner) {
    const int dk = corner & 1, di = corner >> 1;
    const float w = (dk ? ior_weight_ : 1.0f - ior_weight_) * (di ? roughness_weight_ : 1.0f - roughness_weight_);
    const GlassAlbedo* row = kTable[row_of(side, ior_index_ + dk, roughness_index_ + di)];
    sum.total += w * (row[j].total + (row[j + 1].total - row[j].total) * fx);
    sum.reflected += w * (row[j].reflected + (row[j + 1].reflected - row[j].reflected) * fx);
  }
  return sum;
}

float GlassAlbedoLookup::average(int side) const {
  const Derived& d = derived();
  float loss = 0.0f;
  for (int corner = 0; corner < 4; ++corner) {
    const int dk = corner & 1, di = corner >> 1;
    const float w = (dk ? ior_weight_ : 1.0f - ior_weight_) * (di ? roughness_weight_ : 1.0f - roughness_weight_);
    loss += w * d.cumulative_loss[row_of(side, ior_index_ + dk, roughness_index_ + di)][kLastCos];
  }
  return 1.0f - loss;
}

float GlassAlbedoLookup::fresnel_average(int side) const {
  const float* f = derived().fresnel_average[side];
  return f[ior_index_] + (f[ior_index_ + 1] - f[ior_index_]) * ior_weight_;
}

// The interpolated loss is the corners' losses weighted bilinearly, so its density is a mixture:
// a corner in proportion to its weight times its total loss, then a segment of that corner's row in
// proportion to its loss, then s within the segment by inverting the loss integrated over it.
float GlassAlbedoLookup::sample_loss_cos(int side, float u) const {
  const Derived& d = derived();
  double mass[4], total = 0.0;
  int rows[4];
  for (int corner = 0; corner < 4; ++corner) {
    const int dk = corner & 1, di = corner >> 1;
    const float w = (dk ? ior_weight_ : 1.0f - ior_weight_) * (di ? roughness_weight_ : 1.0f - roughness_weight_);
    rows[corner] = row_of(side, ior_index_ + dk, roughness_index_ + di);
    mass[corner] = static_cast<double>(w) * d.cumulative_loss[rows[corner]][kLastCos];
    total += mass[corner];
  }
  if (!(total > 0.0)) return -1.0f;
  double target = static_cast<double>(u) * total;
  int corner = 0;
  while (corner < 3 && (target >= mass[corner] || !(mass[corner] > 0.0))) target -= mass[corner++];
  while (!(mass[corner] > 0.0)) --corner;  // u at the end of the range: the last corner with a loss
  const float* cumulative = d.cumulative_loss[rows[corner]];
  // The target in the corner's own row: its share of the mass, times the row's loss.
  const double in_row = std::clamp(target / mass[corner], 0.0, 1.0) * cumulative[kLastCos];
  int j = 0;
  while (j < kLastCos - 1 && in_row >= cumulative[j + 1]) ++j;
  const LossSegment segment(kTable[rows[corner]], j);
  const double s = segment.solve(std::clamp(in_row - cumulative[j], 0.0, segment.integral(segment.s1)));
  return static_cast<float>(s * s);
}

}  // namespace pxf
