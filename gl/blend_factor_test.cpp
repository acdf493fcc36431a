// The blend factor s (docs/method.md section 3.2) at every case boundary and at extreme magnitudes, for the CPU
// definition (blend_decision) and for the shader (blend.frag through BlendPass).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include "gl/blend_pass.h"
#include "gl/cpu_reference.h"
#include "gl/inputs.h"
#include "gl/test_util.h"

namespace pxf {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// g(s) <= t whenever case 3 applies (tiny relative slack for float rounding).
void check_decision(float u, float f, float t, BlendDecision d) {
  SCOPED_TRACE(testing::Message() << "u=" << u << " f=" << f << " t=" << t);
  ASSERT_TRUE(std::isfinite(d.s));
  ASSERT_GE(d.s, 0.0f);
  ASSERT_LE(d.s, 1.0f);
  if (d.blend_case == kCaseMixed) {
    double s = d.s, g = s * s * double(u) + (1 - s) * (1 - s) * double(f);
    EXPECT_LE(g, double(t) * (1 + 1e-4) + 1e-30);
  }
  if (d.blend_case == kCaseUnfiltered) {
    EXPECT_EQ(d.s, 1.0f);
  }
  if (d.blend_case == kCaseLeastVariance && std::isfinite(u) && std::isfinite(f) && double(u) + f > 0) {
    // No s reaches t: the minimizer of g, f / (u + f), whose g is no more than L_f's alone.
    EXPECT_NEAR(d.s, double(f) / (double(u) + f), 1e-6);
    double s = d.s, g = s * s * double(u) + (1 - s) * (1 - s) * double(f);
    EXPECT_LE(g, double(f) * (1 + 1e-5) + 1e-37);
  }
}

const std::vector<float>& magnitudes() {
  static const std::vector<float> v = {0.0f, 1e-30f, 1e-20f, 1e-10f, 1e-5f, 1e-3f, 0.01f, 0.05f, 0.1f,
                                       0.2f, 0.25f, 0.5f, 1.0f, 2.0f, 10.0f, 1e5f, 1e10f, 1e20f, 1e30f};
  return v;
}
const std::vector<float>& thresholds() {
  static const std::vector<float> v = {0.0f, 1e-30f, 1e-3f, 0.01f, 0.2f, 0.25f, 1.0f, 1e30f};
  return v;
}

TEST(BlendFactorCpu, SpecCases) {
  EXPECT_EQ(blend_decision(0, 0, 0.01f).blend_case, kCaseUnfiltered);  // u = f = 0: case 2
  EXPECT_EQ(blend_factor(0, 0, 0.0f), 1.0f);                          // ... even with t = 0
  EXPECT_EQ(blend_factor(0.5f, 0.0f, 0.0f), 0.0f);                    // t = 0, u > 0: s = 0
  EXPECT_FLOAT_EQ(blend_factor(0.5f, 0.3f, 0.0f), 0.375f);         // ... and f > 0: g's minimizer f / (u + f)
  EXPECT_EQ(blend_decision(0.01f, 0.5f, 0.01f).s, 1.0f);              // u = t: case 2 first
  EXPECT_EQ(blend_decision(0.01f, 0.5f, 0.01f).blend_case, kCaseUnfiltered);
  // D = t u + t f - u f = 0 at t = 0.25, u = f = 0.5: case 3 with s = f / (u + f).
  BlendDecision d = blend_decision(0.5f, 0.5f, 0.25f);
  EXPECT_EQ(d.blend_case, kCaseMixed);
  EXPECT_FLOAT_EQ(d.s, 0.5f);
  // Just past D = 0: case 1.
  EXPECT_EQ(blend_decision(0.5f, 0.5001f, 0.25f).blend_case, kCaseLeastVariance);
  // f = 0 and u > t: s = sqrt(t / u).
  EXPECT_NEAR(blend_factor(0.04f, 0.0f, 0.01f), 0.5f, 1e-6f);
  // L_b = 0: relative variances are infinite (or 0 without noise).
  EXPECT_EQ(relative_variance(1.0f, 0.0f), kInf);
  EXPECT_EQ(relative_variance(0.0f, 0.0f), 0.0f);
  EXPECT_EQ(relative_variance(1e30f, 1e-30f), kInf);
  EXPECT_EQ(blend_factor(kInf, kInf, 0.01f), 0.5f);
  EXPECT_EQ(blend_factor(kInf, 0.0f, 0.01f), 0.0f);
  EXPECT_EQ(blend_factor(0.0f, kInf, 0.01f), 1.0f);
  // Non-finite inputs stay finite.
  for (float x : {kNaN, kInf, -kInf, -1.0f})
    for (float y : {kNaN, kInf, 0.0f, 0.5f})
      for (float t : {kNaN, -1.0f, 0.0f, 0.01f, kInf}) {
        float s = blend_factor(x, y, t);
        EXPECT_TRUE(s >= 0.0f && s <= 1.0f) << x << " " << y << " " << t;
      }
}

TEST(BlendFactorCpu, GridAndRandomExtremes) {
  for (float t : thresholds())
    for (float u : magnitudes())
      for (float f : magnitudes()) check_decision(u, f, t, blend_decision(u, f, t));
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> e(-30.0f, 30.0f);
  for (int i = 0; i < 200000; ++i) {
    float u = std::pow(10.0f, e(rng)), f = std::pow(10.0f, e(rng)), t = std::pow(10.0f, e(rng) / 10.0f - 1.0f);
    check_decision(u, f, t, blend_decision(u, f, t));
  }
}

// The covariance term: g(s) = s^2 u + (1-s)^2 f + 2 s (1-s) w u, with the filter's centre weight w.
double blend_variance(double s, double u, double f, double w) {
  const double c = std::min(w * u, std::sqrt(u * f));
  return s * s * u + (1 - s) * (1 - s) * f + 2 * s * (1 - s) * c;
}

TEST(BlendFactorCpu, CovarianceTermZeroWeightIsThePlainBlend) {
  for (float t : thresholds())
    for (float u : magnitudes())
      for (float f : magnitudes()) {
        const BlendDecision a = blend_decision(u, f, t), b = blend_decision(u, f, t, 0.0f);
        EXPECT_EQ(a.s, b.s);
        EXPECT_EQ(a.blend_case, b.blend_case);
      }
}

TEST(BlendFactorCpu, CovarianceTermHitsTheThreshold) {
  // By hand: u = 0.04, f = 0.01, w = 0.25, t = 0.01. Without the term s = 0.4, whose true variance
  // is 0.0064 + 0.0036 + 0.0048 = 0.0148 = 1.48 t; with it the minimum of g is f itself, s = 0.
  EXPECT_NEAR(blend_decision(0.04f, 0.01f, 0.01f).s, 0.4f, 1e-6f);
  EXPECT_NEAR(blend_variance(0.4, 0.04, 0.01, 0.25), 0.0148, 1e-9);
  EXPECT_NEAR(blend_decision(0.04f, 0.01f, 0.01f, 0.25f).s, 0.0f, 1e-6f);
  // u = 0.04, f = 0.005: s = -0.2 + sqrt(0.006 / 0.025) = 0.28990.
  const BlendDecision d = blend_decision(0.04f, 0.005f, 0.01f, 0.25f);
  EXPECT_EQ(d.blend_case, kCaseMixed);
  EXPECT_NEAR(d.s, -0.2 + std::sqrt(0.24), 1e-6);
  // w = 1 and f = u: the filter returned the pixel itself, g(s) = u > t for every s: case 1.
  EXPECT_EQ(blend_decision(0.04f, 0.04f, 0.01f, 1.0f).blend_case, kCaseLeastVariance);
  // Random u, f >= w^2 u (the filter's variance holds the centre's share), t and w: s in [0, 1]; in
  // case 3 g(s) = t unless s was clamped to 1; in case 1 t lies below g on all of [0, 1] (sampled).
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> e(-6.0f, 2.0f), unit(0.0f, 1.0f);
  int mixed = 0;
  for (int i = 0; i < 100000; ++i) {
    const float u = std::pow(10.0f, e(rng)), w = unit(rng), t = std::pow(10.0f, e(rng) / 2.0f - 1.0f);
    const float f = w * w * u + std::pow(10.0f, e(rng));
    const BlendDecision d = blend_decision(u, f, t, w);
    SCOPED_TRACE(testing::Message() << "u=" << u << " f=" << f << " t=" << t << " w=" << w);
    ASSERT_TRUE(d.s >= 0.0f && d.s <= 1.0f);
    if (d.blend_case == kCaseMixed && d.s < 1.0f) {
      ++mixed;
      ASSERT_NEAR(blend_variance(d.s, u, f, w), t, 1e-4 * t + 1e-6 * std::max(u, f));
    }
    if (d.blend_case == kCaseLeastVariance) {
      for (int k = 0; k <= 100; ++k) ASSERT_GT(blend_variance(k / 100.0, u, f, w), t * (1 - 1e-4));
    }
    if (d.blend_case == kCaseUnfiltered) {
      ASSERT_LE(u, t);
    }
  }
  EXPECT_GT(mixed, 1000);
}

// The bias guard's factor (shaders/pass_formulas.h): the s in [0, 1] of least expected squared
// error (1-s)^2 (b2 + f) + s^2 u + 2 s (1-s) c, found here by a fine search, but never below the
// blend's own s; the case becomes kCaseBiasGuard only where it raised s, and no bias changes nothing.
double expected_squared_error(double s, double u, double f, double w, double b2) {
  return (1 - s) * (1 - s) * b2 + blend_variance(s, u, f, w);
}

TEST(BlendFactorCpu, BiasGuardRaisesSToTheLeastErrorAndNeverLowersIt) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> e(-6.0f, 1.0f), unit(0.0f, 1.0f);
  int raised = 0;
  for (int i = 0; i < 20000; ++i) {
    const float u = std::pow(10.0f, e(rng)), w = unit(rng), s0 = unit(rng);
    const float f = w * w * u + std::pow(10.0f, e(rng)), b2 = std::pow(10.0f, e(rng));
    SCOPED_TRACE(testing::Message() << "u=" << u << " f=" << f << " w=" << w << " b2=" << b2 << " s0=" << s0);
    int blend_case = kCaseMixed;
    const float s = shared::bias_guard_factor(s0, u, f, w, b2, blend_case);
    ASSERT_GE(s, s0);
    ASSERT_LE(s, 1.0f);
    double best_s = 0, best = expected_squared_error(0, u, f, w, b2);
    for (int k = 1; k <= 10000; ++k) {
      const double e_k = expected_squared_error(k / 10000.0, u, f, w, b2);
      if (e_k < best) best = e_k, best_s = k / 10000.0;
    }
    if (best_s > s0 + 1e-3) {
      ASSERT_EQ(blend_case, kCaseBiasGuard);
      ASSERT_NEAR(s, best_s, 2e-4);
      ++raised;
    } else if (best_s < s0 - 1e-3) {
      ASSERT_EQ(s, s0);
      ASSERT_EQ(blend_case, kCaseMixed);
    }
    int unchanged = kCaseLeastVariance;
    ASSERT_EQ(shared::bias_guard_factor(s0, u, f, w, 0.0f, unchanged), s0);
    ASSERT_EQ(unchanged, kCaseLeastVariance);
  }
  EXPECT_GT(raised, 2000);
  // By hand: u = 0.04, f = 0, w = 0, b2 = 0.01: s = 0.01 / 0.05 = 0.2 (from the blend's 0.1).
  int c = kCaseMixed;
  EXPECT_NEAR(shared::bias_guard_factor(0.1f, 0.04f, 0.0f, 0.0f, 0.01f, c), 0.2f, 1e-6f);
  EXPECT_EQ(c, kCaseBiasGuard);
  // Non-finite variances: s unchanged.
  c = kCaseMixed;
  EXPECT_EQ(shared::bias_guard_factor(0.3f, kInf, 0.0f, 0.0f, 0.01f, c), 0.3f);
  EXPECT_EQ(shared::bias_guard_factor(0.3f, 0.1f, kNaN, 0.0f, 0.01f, c), 0.3f);
  EXPECT_EQ(c, kCaseMixed);
}

// s from the shader for (u, f) pairs: L_lv = 0, L_f = (1,1,1) so L_b = 1, Var[L_u] = u, Var[L_f] = f.
TEST(BlendFactorShader, MatchesCpuOnGridAndBoundaries) {
  test::osmesa_context();
  const auto& mags = magnitudes();
  const int w = static_cast<int>(mags.size()), h = w + 1;
  Image lv = Image::rgb(w, h), hv = Image::rgb(w, h, 1.0f), var = Image::gray(w, h);
  Image filtered = Image::rgba(w, h, 1.0f);
  for (int y = 0; y < w; ++y)
    for (int x = 0; x < w; ++x) {
      var.at(x, y, 0) = mags[y];
      filtered.at(x, y, 3) = mags[x];
    }
  // Last row: D = 0 (t = 0.25), n < 2, L_b = 0 with noise, L_b = 0 without noise, tiny L_b.
  const int r = w;
  var.at(0, r, 0) = 0.5f, filtered.at(0, r, 3) = 0.5f;
  var.at(1, r, 0) = kVarUnknown;
  var.at(2, r, 0) = 0.3f;
  for (int c = 0; c < 3; ++c) filtered.at(2, r, c) = 0.0f;
  var.at(3, r, 0) = 0.0f, filtered.at(3, r, 3) = 0.0f;
  for (int c = 0; c < 3; ++c) filtered.at(3, r, c) = 0.0f;
  var.at(4, r, 0) = 1e30f, filtered.at(4, r, 3) = 1e-30f;
  for (int c = 0; c < 3; ++c) filtered.at(4, r, c) = 1e-30f;
  // All samples equal (Var[L_u] = 0, n >= 2): u = (Y(L_f) / L_b)^2. Bright L_f, f = 0: u = 1.
  var.at(5, r, 0) = 0.0f, filtered.at(5, r, 3) = 0.0f;
  // ... all samples zero, L_f tiny against L_lv: u = (1e-3 / 1.001)^2, case 2 for t >= 1e-6.
  var.at(6, r, 0) = 0.0f, filtered.at(6, r, 3) = 0.0f;
  for (int c = 0; c < 3; ++c) hv.at(6, r, c) = 0.0f, lv.at(6, r, c) = 1.0f, filtered.at(6, r, c) = 1e-3f;
  PreviewInputs inputs(w, h);
  inputs.upload(lv, hv, var);
  Texture2D ftex(w, h, TextureFormat::RGBA32F);
  ftex.upload(filtered);
  BlendPass blend(w, h);
  for (float t : thresholds()) {
    blend.run(inputs, &ftex, nullptr, t, {});
    Image s = blend.s_image(), cases = blend.case_image(), final_rgb = blend.final_image();
    EXPECT_EQ(count_nonfinite(final_rgb), 0u);
    for (int y = 0; y < w; ++y)
      for (int x = 0; x < w; ++x) {
        // L_b = Y(L_f) = 1 here; Var[L_u] = 0 means all samples equal: u = zero_variance_u(1, 1, n) = 1 (n unknown).
        float u = mags[y] > 0.0f ? mags[y] : zero_variance_u(1.0f, 1.0f, 0.0f), f = mags[x];
        BlendDecision ref = blend_decision(u, f, t);
        BlendDecision gpu{s.at(x, y, 0), static_cast<int>(cases.at(x, y, 0))};
        check_decision(u, f, t, gpu);
        EXPECT_EQ(gpu.blend_case, ref.blend_case) << "u=" << u << " f=" << f << " t=" << t;
        EXPECT_NEAR(gpu.s, ref.s, 1e-5f + 1e-4f * ref.s) << "u=" << u << " f=" << f << " t=" << t;
      }
    if (t == 0.25f) {
      EXPECT_EQ(cases.at(0, r, 0), float(kCaseMixed));
      EXPECT_NEAR(s.at(0, r, 0), 0.5f, 1e-6f);
    }
    EXPECT_EQ(cases.at(1, r, 0), float(kCaseUnknownVar));  // n < 2: s = 0
    EXPECT_EQ(s.at(1, r, 0), 0.0f);
    EXPECT_EQ(s.at(2, r, 0), 0.5f);                        // L_b = 0 with noise: u = f = inf, g least at 1/2
    EXPECT_EQ(s.at(3, r, 0), 1.0f);                        // L_b = 0, no noise: case 2
    EXPECT_NEAR(s.at(5, r, 0), std::min(1.0f, std::sqrt(t)), 1e-6f);  // g(s) = s^2 u = t
    if (t >= 1e-6f) {
      EXPECT_EQ(cases.at(6, r, 0), float(kCaseUnfiltered));
    }
    if (t == 0.0f) {
      EXPECT_EQ(s.at(6, r, 0), 0.0f);
    }
    for (float v : s.pixels) EXPECT_TRUE(v >= 0.0f && v <= 1.0f);
  }
}

// The kernel sums every filter variant shares (shaders/pass_formulas.h), against the formulas
// written out: L_f = sum w L / sum w; Var[L_f] = (sum_known w^2 v + sum_unknown w^2 * vbar) / (sum w)^2
// with vbar = sum_known w v / sum_known w.
TEST(KernelSums, MeanAndVarianceWithUnknownNeighbours) {
  shared::KernelSums s = shared::kernel_sums_zero();
  shared::kernel_sums_add(s, 1.0, glm::vec3(1.0f, 2.0f, 3.0f), 0.04f);
  shared::kernel_sums_add(s, 0.5, glm::vec3(3.0f, 0.0f, 1.0f), 0.16f);
  shared::kernel_sums_add(s, 0.25, glm::vec3(5.0f, 4.0f, 0.0f), kVarUnknown);  // n < 2
  shared::kernel_sums_add(s, 0.25, glm::vec3(1.0f, 0.0f, 0.0f), 0.0f);         // all samples equal
  const double sw = 2.0;
  const glm::vec3 mean = shared::kernel_sums_mean(s);
  EXPECT_FLOAT_EQ(mean.r, float((1.0 + 1.5 + 1.25 + 0.25) / sw));
  EXPECT_FLOAT_EQ(mean.g, float((2.0 + 0.0 + 1.0 + 0.0) / sw));
  EXPECT_FLOAT_EQ(mean.b, float((3.0 + 0.5 + 0.0 + 0.0) / sw));
  const double vbar = (1.0 * 0.04 + 0.5 * 0.16) / 1.5;
  const double var = (1.0 * 0.04 + 0.25 * 0.16 + 2 * 0.0625 * vbar) / (sw * sw);
  EXPECT_NEAR(shared::kernel_sums_variance(s, 1.0f), var, 1e-8);
  EXPECT_NEAR(shared::kernel_sums_variance(s, 3.0f), 3.0 * var, 3e-8);
  // No known variance at all: unknown.
  shared::KernelSums unknown = shared::kernel_sums_zero();
  shared::kernel_sums_add(unknown, 1.0, glm::vec3(1.0f), 0.0f);
  EXPECT_EQ(shared::kernel_sums_variance(unknown, 1.0f), kVarUnknown);
}

// 5x3: range color 0.5 for x <= 2, 0.1 for x >= 3 (an edge), equal depth.
struct PoolingScene {
  Image range = Image::rgb(5, 3), depth = Image::gray(5, 3, "Y", 2.0f), var = Image::gray(5, 3);
  PoolingScene() {
    for (int y = 0; y < 3; ++y)
      for (int x = 0; x < 5; ++x) {
        for (int c = 0; c < 3; ++c) range.at(x, y, c) = x <= 2 ? 0.5f : 0.1f;
        var.at(x, y, 0) = x <= 2 ? 1e-2f : 1.0f;
      }
  }
};

TEST(PooledVariance, QuietPixelTakesTheMeanOfItsRangeNeighbours) {
  PoolingScene p;
  p.var.at(1, 1, 0) = 1e-6f;  // a pixel that missed the bright paths
  const RangeWeights range = range_weights(FilterParams{});
  EXPECT_NEAR(pooled_var_u(p.var, p.range, p.depth, 1, 1, range), (8 * 1e-2f + 1e-6f) / 9, 1e-8f);
  // Across the range edge the noisier right side does not count: (2,1) keeps its own 1e-2.
  EXPECT_FLOAT_EQ(pooled_var_u(p.var, p.range, p.depth, 2, 1, range), 1e-2f);
  // Without a color term (k_c = 0) it would: the mean then includes the right side's 1.0.
  EXPECT_GT(pooled_var_u(p.var, p.range, p.depth, 2, 1, RangeWeights{0.0f, 0.0f}), 0.2f);
  // Own variance unknown (n < 2) stays unknown; zero (all samples equal) takes the neighbours'.
  p.var.at(1, 1, 0) = kVarUnknown;
  EXPECT_EQ(pooled_var_u(p.var, p.range, p.depth, 1, 1, range), kVarUnknown);
  p.var.at(1, 1, 0) = 0.0f;
  EXPECT_NEAR(pooled_var_u(p.var, p.range, p.depth, 1, 1, range), 1e-2f, 1e-8f);
  // All samples equal and no neighbour variance known: 0 (the blend then uses zero_variance_u).
  for (float& v : p.var.pixels) v = 0.0f;
  EXPECT_EQ(pooled_var_u(p.var, p.range, p.depth, 1, 1, range), 0.0f);
}

// The zero-variance rule: u = (Y(L_f) / L_b)^2 up to kZeroVarianceSamples samples, then falling as
// 1 / n, so that a pixel whose samples are all 0 leaves the filter (its bias vanishes) once it
// has enough of them; and pixel_samples reads each pixel's own count back from its threshold factor.
TEST(ZeroVarianceRule, FallsAsOneOverNFromKSamples) {
  EXPECT_EQ(zero_variance_u(0.5f, 2.0f, 0.0f), 0.0625f);  // n unknown: no decay
  EXPECT_EQ(zero_variance_u(0.5f, 2.0f, 64.0f), 0.0625f);
  EXPECT_EQ(zero_variance_u(0.5f, 2.0f, kZeroVarianceSamples), 0.0625f);
  EXPECT_FLOAT_EQ(zero_variance_u(0.5f, 2.0f, 4 * kZeroVarianceSamples), 0.0625f / 4);
  EXPECT_FLOAT_EQ(zero_variance_u(0.5f, 2.0f, 1e6f), 0.0625f * kZeroVarianceSamples / 1e6f);
  EXPECT_EQ(zero_variance_u(0.0f, 2.0f, 1e6f), 0.0f);  // black L_f: nothing to blend in
  EXPECT_EQ(zero_variance_u(0.5f, 0.0f, 1e6f), kInf);
  // A pixel of L_f = L_b at t = 0.01 is clean (u <= t) from 1024 / 0.01 samples on, not before.
  EXPECT_GT(zero_variance_u(1.0f, 1.0f, 1e5f), 0.01f);
  EXPECT_LE(zero_variance_u(1.0f, 1.0f, 1.03e5f), 0.01f);
}

TEST(ZeroVarianceRule, PixelSamplesInvertTheThresholdFactor) {
  for (uint64_t run : {16u, 1024u, 40000u})
    for (uint64_t own : {5u, 64u, 1000u, 40000u, 1000000u}) {
      const float factor = effective_threshold(0.01f, own) / effective_threshold(0.01f, run);
      // The factor is a float near 1: n_p comes back to 0.2 % up to 40000 samples, 10 % at 1e6
      // (enough for a decay that only has to fall as 1 / n).
      EXPECT_NEAR(pixel_samples(static_cast<float>(run), factor), static_cast<float>(own), (own > 40000 ? 0.1f : 2e-3f) * own)
          << run << " " << own;
    }
  EXPECT_EQ(pixel_samples(40000.0f, 1.0f), 40000.0f);  // a uniform frame's pixels: exactly n
  EXPECT_EQ(pixel_samples(0.0f, 0.5f), 0.0f);          // n unknown
  EXPECT_EQ(pixel_samples(1024.0f, effective_threshold(0.01f, 2) / effective_threshold(0.01f, 1024)), 4.0f);
}

TEST(PooledVariance, DarkSpeckleIsFilteredNotKept) {
  PoolingScene p;
  Image lv = Image::rgb(5, 3), hv = Image::rgb(5, 3, 1.0f);
  FilterOutput filtered{Image::rgb(5, 3, 1.0f), Image::gray(5, 3, "Y", 1e-4f), Image{}};
  for (int c = 0; c < 3; ++c) hv.at(1, 1, c) = 0.01f;  // few small samples: mean and variance tiny
  p.var.at(1, 1, 0) = 1e-7f;
  // Pooled u = (8e-2 + 1e-7) / 9 / L_b^2 with L_b = Y(L_f) = 1: above t = 0.005.
  const float t = 0.005f;
  const BlendParams params{range_weights(FilterParams{})};
  BlendOutput own_only = cpu_blend(lv, hv, p.var, &filtered, t, params, nullptr, nullptr);
  EXPECT_EQ(own_only.blend_case.at(1, 1, 0), float(kCaseUnfiltered));  // u = 1e-7: kept dark
  BlendOutput pooled = cpu_blend(lv, hv, p.var, &filtered, t, params, &p.range, &p.depth);
  EXPECT_NE(pooled.blend_case.at(1, 1, 0), float(kCaseUnfiltered));
  // Case 3: s = (f + sqrt(D)) / (u + f) ~ 0.75, so L ~ 0.75 * 0.01 + 0.25 * 1 instead of 0.01.
  EXPECT_NEAR(pooled.final_rgb.at(1, 1, 1), 0.26f, 0.02f);
}

// effective_threshold: t (n-3)/(n-1), the n = 4 factor below, increasing towards t.
TEST(EffectiveThreshold, ScalesTByTheInverseVarianceBias) {
  EXPECT_FLOAT_EQ(effective_threshold(0.01f, 16), 0.01f * 13.0f / 15.0f);
  for (uint64_t n : {0, 1, 2, 3, 4}) EXPECT_FLOAT_EQ(effective_threshold(0.003f, n), 0.001f);
  float previous = 0.0f;
  for (uint64_t n = 4; n < 5000; n = n * 3 / 2 + 1) {
    const float t = effective_threshold(0.01f, n);
    EXPECT_GT(t, previous);
    EXPECT_LT(t, 0.01f);
    previous = t;
  }
  EXPECT_NEAR(effective_threshold(0.01f, 1000000), 0.01f, 1e-7f);
}

// Why the threshold is scaled: a pixel of n Gaussian samples and an exact, noise-free L_f (f = 0,
// L_b = 1). The blend takes s from the estimated u = S^2 / n, so the final pixel's variance over
// many trials is E[s^2] Var[mean] = t E[u / u_hat] = t (n-1)/(n-3) with t itself (15 % over at 16
// samples), and t with the effective threshold. The sample mean and variance of Gaussian samples are
// independent, which makes this exact; 200,000 trials give about 0.5 % standard error.
double realized_over_t(float t, int n, bool effective) {
  std::mt19937_64 rng(1234);
  std::normal_distribution<double> sample(1.0, 1.0);
  const int trials = 200000;
  double sum = 0, sum2 = 0;
  for (int i = 0; i < trials; ++i) {
    double m = 0, m2 = 0;
    for (int k = 0; k < n; ++k) {
      const double x = sample(rng);
      m += x;
      m2 += x * x;
    }
    const double mean = m / n, s2 = (m2 - m * mean) / (n - 1);
    const float u_hat = static_cast<float>(s2 / n);
    const float s = blend_decision(u_hat, 0.0f, effective ? effective_threshold(t, n) : t).s;
    const double final_value = s * mean + (1.0 - s) * 1.0;
    sum += final_value;
    sum2 += final_value * final_value;
  }
  const double mean = sum / trials;
  return (sum2 / trials - mean * mean) / t;
}

TEST(EffectiveThreshold, RealizedPerceivedVarianceMatchesTOnAverage) {
  for (int n : {8, 16, 64}) {
    SCOPED_TRACE(n);
    EXPECT_NEAR(realized_over_t(0.004f, n, /*effective=*/true), 1.0, 0.025);
    EXPECT_NEAR(realized_over_t(0.004f, n, /*effective=*/false), (n - 1.0) / (n - 3.0), 0.025);
  }
}

// noise_sigma_s: sqrt((u / t) / (4 pi)) at the 0.9-quantile of the noisy pixels' u / t, between
// 2 px and sigma_s; sigma_s up to 4 spp; a sigma_s below 2 is kept, never widened.
TEST(SigmaShrink, SizesTheKernelForTheNoisiestTenthOfThePixels) {
  auto sigma = [](float sigma_s, uint64_t n, std::vector<float> needed) { return noise_sigma_s(sigma_s, n, needed); };
  const float pi4 = 4.0f * 3.14159265f;
  // 100 pixels of ratio 1..100: the 0.9-quantile (index 90) is 91.
  std::vector<float> ramp;
  for (int i = 100; i >= 1; --i) ramp.push_back(float(i));
  EXPECT_NEAR(sigma(8.0f, 64, ramp), std::sqrt(91.0f / pi4), 1e-4);
  for (uint64_t n : {0, 1, 2, 3, 4}) EXPECT_EQ(sigma(8.0f, n, ramp), 8.0f);
  EXPECT_EQ(sigma(8.0f, 64, {}), kSigmaShrinkMin);                      // nothing above t
  EXPECT_EQ(sigma(8.0f, 64, std::vector<float>(10, 4.0f)), kSigmaShrinkMin);  // needs under 2 px
  EXPECT_EQ(sigma(8.0f, 64, std::vector<float>(10, 1e6f)), 8.0f);       // needs more than sigma_s
  EXPECT_EQ(sigma(8.0f, 64, {std::numeric_limits<float>::infinity()}), 8.0f);
  EXPECT_EQ(sigma(8.0f, 64, {std::nanf("")}), 8.0f);
  EXPECT_EQ(sigma(1.5f, 1000, ramp), 1.5f);
  // Ten times the noise: sqrt(10) times the kernel.
  std::vector<float> louder;
  for (float r : ramp) louder.push_back(10.0f * r);
  EXPECT_NEAR(sigma(16.0f, 64, louder) / sigma(16.0f, 64, ramp), std::sqrt(10.0f), 1e-4);
}

}  // namespace
}  // namespace pxf
