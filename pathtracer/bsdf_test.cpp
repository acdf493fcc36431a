// BSDF sampling against its pdf (chi-square), sample weights against eval/pdf, glass branches.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "pathtracer/bsdf.h"
#include "pathtracer/ggx_albedo.h"
#include "pathtracer/glass_albedo.h"
#include "pathtracer/rng.h"
#include "testing/shapes.h"
#include "testing/stat_tests.h"

namespace pxf {
namespace {

constexpr int kThetaBins = 16, kPhiBins = 32;
constexpr int kSamples = 200000;

struct Case {
  const char* name;
  BsdfParams params;
  float incident_degrees;
  bool front_face = true;  // false: wo inside the medium (eta = 1 / ior)
};

BsdfParams conductor(glm::vec3 f0, float roughness) {
  BsdfParams p;
  p.base_color = f0;
  p.metallic = 1.0f;
  p.roughness = roughness;
  return p;
}

BsdfParams plastic(glm::vec3 base, float roughness, float metallic = 0.0f) {
  BsdfParams p;
  p.base_color = base;
  p.metallic = metallic;
  p.roughness = roughness;
  return p;
}

BsdfParams lambert(glm::vec3 albedo) {
  BsdfParams p;
  p.base_color = albedo;
  p.metallic = 0.0f;
  p.specular = 0.0f;
  return p;
}

BsdfParams rough_glass(float roughness, glm::vec3 tint = glm::vec3(1.0f), float ior = 1.5f) {
  BsdfParams p;
  p.base_color = tint;
  p.metallic = 0.0f;
  p.roughness = roughness;
  p.transmission = 1.0f;
  p.ior = ior;
  return p;
}

BsdfParams coated(BsdfParams base, float clearcoat, float coat_roughness) {
  base.clearcoat = clearcoat;
  base.clearcoat_roughness = coat_roughness;
  return base;
}

BsdfParams sheened(BsdfParams base, glm::vec3 sheen_color, float sheen_roughness) {
  base.sheen_color = sheen_color;
  base.sheen_roughness = sheen_roughness;
  return base;
}

// Diffuse, glossy and rough glass lobes at once.
BsdfParams half_glass() {
  BsdfParams p = plastic(glm::vec3(0.6f, 0.7f, 0.8f), 0.5f);
  p.transmission = 0.5f;
  return p;
}

// Bin of a direction in (cos theta in [-1, 1], phi) around the z axis (the normal).
int bin_of(glm::vec3 w) {
  int ti = std::min(kThetaBins - 1, std::max(0, static_cast<int>((w.z + 1.0f) * 0.5f * kThetaBins)));
  float phi = std::atan2(w.y, w.x);
  if (phi < 0) phi += 2.0f * kPi;
  int pi = std::min(kPhiBins - 1, std::max(0, static_cast<int>(phi / (2.0f * kPi) * kPhiBins)));
  return ti * kPhiBins + pi;
}

// Integrates pdf over every bin with a fine midpoint rule (dω = d cos(theta) d phi).
std::vector<double> expected_counts(const Bsdf& bsdf, double n) {
  const int sub = 16;
  std::vector<double> expected(kThetaBins * kPhiBins, 0.0);
  double dz = 2.0 / (kThetaBins * sub), dphi = 2.0 * M_PI / (kPhiBins * sub);
  for (int t = 0; t < kThetaBins * sub; ++t) {
    double z = -1.0 + (t + 0.5) * dz;
    double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    for (int p = 0; p < kPhiBins * sub; ++p) {
      double phi = (p + 0.5) * dphi;
      glm::vec3 w(static_cast<float>(r * std::cos(phi)), static_cast<float>(r * std::sin(phi)), static_cast<float>(z));
      expected[(t / sub) * kPhiBins + p / sub] += bsdf.pdf(w) * dz * dphi * n;
    }
  }
  return expected;
}

TEST(Bsdf, SamplingMatchesPdfChiSquare) {
  const std::vector<Case> cases = {
      {"lambert normal", lambert(glm::vec3(0.8f)), 0.0f},
      {"lambert grazing", lambert(glm::vec3(0.8f)), 70.0f},
      {"conductor r0.3 10deg", conductor(glm::vec3(0.9f, 0.6f, 0.3f), 0.3f), 10.0f},
      {"conductor r0.3 60deg", conductor(glm::vec3(0.9f, 0.6f, 0.3f), 0.3f), 60.0f},
      {"conductor r0.6 45deg", conductor(glm::vec3(1.0f), 0.6f), 45.0f},
      {"conductor r1 80deg", conductor(glm::vec3(1.0f), 1.0f), 80.0f},
      {"plastic r0.25 30deg", plastic(glm::vec3(0.5f), 0.25f), 30.0f},
      {"plastic r0.5 75deg", plastic(glm::vec3(0.2f, 0.4f, 0.8f), 0.5f), 75.0f},
      {"half metal r0.4 40deg", plastic(glm::vec3(0.7f, 0.5f, 0.3f), 0.4f, 0.5f), 40.0f},
      {"half glass r0.5 35deg", half_glass(), 35.0f},
      // Entering, the refracted lobe is about a third as wide as the microfacets' tilt: narrower than
      // the bins' integration resolution below roughness 0.5 (leaving, it widens).
      {"rough glass r1 0deg", rough_glass(1.0f), 0.0f},
      {"rough glass r0.5 50deg", rough_glass(0.5f, glm::vec3(0.9f, 0.7f, 0.5f)), 50.0f},
      {"rough glass r0.6 75deg", rough_glass(0.6f), 75.0f},
      {"rough glass r1 30deg", rough_glass(1.0f), 30.0f},
      {"rough glass inside r0.3 20deg", rough_glass(0.3f), 20.0f, false},
      {"rough glass inside r0.5 40deg", rough_glass(0.5f), 40.0f, false},
      {"rough glass inside r0.8 70deg", rough_glass(0.8f), 70.0f, false},
      // Where the compensation lobe carries much of the light (58 % inside at roughness 1, normal
      // incidence), at other iors, between the table's points and beyond its last ior (3.44).
      {"rough glass inside r1 0deg", rough_glass(1.0f), 0.0f, false},
      {"rough glass ior 2.4 r0.8 60deg", rough_glass(0.8f, glm::vec3(0.8f, 0.9f, 1.0f), 2.4f), 60.0f},
      {"rough glass inside ior 1.2 r0.9 40deg", rough_glass(0.9f, glm::vec3(1.0f), 1.2f), 40.0f, false},
      {"rough glass inside ior 4 r0.7 15deg", rough_glass(0.7f, glm::vec3(1.0f), 4.0f), 15.0f, false},
      {"coat r0.2 over plastic r0.6 30deg", coated(plastic(glm::vec3(0.6f, 0.3f, 0.2f), 0.6f), 1.0f, 0.2f), 30.0f},
      {"coat r0.5 over metal r0.3 70deg", coated(conductor(glm::vec3(0.9f, 0.6f, 0.3f), 0.3f), 0.7f, 0.5f), 70.0f},
      {"coat r0.3 over rough glass 45deg", coated(rough_glass(0.5f), 1.0f, 0.3f), 45.0f},
      {"smooth coat over plastic r0.5 20deg", coated(plastic(glm::vec3(0.5f), 0.5f), 1.0f, 0.0f), 20.0f},
      {"sheen r0.5 over plastic 40deg", sheened(plastic(glm::vec3(0.4f), 0.7f), glm::vec3(1.0f, 0.8f, 0.6f), 0.5f), 40.0f},
      {"sheen r0.2 over black 75deg", sheened(lambert(glm::vec3(0.0f)), glm::vec3(0.9f), 0.2f), 75.0f},
      {"sheen r1 under coat over metal 10deg",
       coated(sheened(conductor(glm::vec3(0.8f), 0.4f), glm::vec3(0.5f), 1.0f), 0.5f, 0.3f), 10.0f},
  };
  const double alpha = 0.01 / cases.size();  // Bonferroni
  for (const Case& c : cases) {
    float theta = glm::radians(c.incident_degrees);
    glm::vec3 wo(std::sin(theta), 0.0f, std::cos(theta));
    Bsdf bsdf(c.params, glm::vec3(0, 0, 1), glm::vec3(0, 0, 1), wo, c.front_face);
    ASSERT_TRUE(bsdf.has_nondelta()) << c.name;
    // The direction bins, then one bin for samples without a non-delta direction (the delta glass
    // branch, or a microfacet normal that reflects below the horizon): pdf() integrates to the
    // probability of a non-delta direction, the rest is that bin's.
    std::vector<double> observed(kThetaBins * kPhiBins + 1, 0.0);
    Rng rng(11, static_cast<uint64_t>(&c - cases.data()), 0);
    int weight_mismatches = 0;
    for (int i = 0; i < kSamples; ++i) {
      float u_lobe = rng.next_float();
      glm::vec2 u = rng.next_2d();
      BsdfSample s;
      if (!bsdf.sample(u_lobe, u, &s) || s.delta) {
        observed.back() += 1.0;
        continue;
      }
      observed[bin_of(s.wi)] += 1.0;
      if (s.transmitted != (s.wi.z < 0.0f)) ++weight_mismatches;
      // The sample's pdf and weight agree with pdf() and eval() / pdf().
      float pdf = bsdf.pdf(s.wi);
      glm::vec3 expect_weight = bsdf.eval(s.wi) / pdf;
      if (std::abs(pdf - s.pdf) > 1e-3f * pdf || glm::length(expect_weight - s.weight) > 1e-3f * (1.0f + glm::length(s.weight)))
        ++weight_mismatches;
    }
    EXPECT_EQ(weight_mismatches, 0) << c.name;
    std::vector<double> expected = expected_counts(bsdf, kSamples);
    double non_delta = 0;
    for (double e : expected) non_delta += e;
    expected.push_back(std::max(0.0, kSamples - non_delta));
    stat::ChiSquareResult r = stat::chi_square(observed, expected);
    EXPECT_TRUE(r.problem.empty()) << c.name << ": " << r.problem;
    EXPECT_GT(r.p_value, alpha) << c.name << ": chi2 = " << r.statistic << ", dof = " << r.dof;
  }
}

TEST(Bsdf, EvalAndPdfMatchTheWrittenOutModel) {
  // f cos and the pdf against the model written out term by term (docs/materials.md), so that a
  // rearranged implementation (precomputed Fresnel terms, reciprocals) cannot drift from it: the
  // diffuse lobe c_d base / pi (1 - F_d(cos_o)), the GGX lobe with the metal's and the dielectric's
  // Schlick Fresnel at the half vector, both compensated by Turquin's 1 + F0 (1 / E - 1) with the
  // tabulated albedo E (checked in ggx_albedo_test.cpp), and the lobe choice by the lobes' albedos.
  auto schlick = [](glm::vec3 f0, float f90, float c) {
    return f0 + (glm::vec3(f90) - f0) * std::pow(1.0f - c, 5.0f);
  };
  auto lambda = [](glm::vec3 w, float alpha) {
    return 0.5f * (-1.0f + std::sqrt(1.0f + alpha * alpha * (1.0f - w.z * w.z) / (w.z * w.z)));
  };
  const glm::vec3 n(0, 0, 1);
  const glm::vec3 wo = glm::normalize(glm::vec3(0.3f, -0.2f, 0.6f));
  const glm::vec3 wi = glm::normalize(glm::vec3(-0.5f, 0.1f, 0.4f));
  for (float metallic : {0.0f, 0.4f, 1.0f})
    for (float roughness : {0.3f, 1.0f})
      for (float specular : {0.5f, 1.0f}) {
        SCOPED_TRACE(::testing::Message() << "metallic " << metallic << " roughness " << roughness << " specular " << specular);
        BsdfParams p;
        p.base_color = glm::vec3(0.8f, 0.4f, 0.2f);
        p.metallic = metallic;
        p.roughness = roughness;
        p.specular = specular;
        p.specular_color = glm::vec3(1.0f, 0.9f, 0.8f);
        p.ior = 1.45f;
        const Bsdf bsdf(p, n, n, wo, true);
        float pdf = 0.0f;
        const glm::vec3 f = bsdf.eval(wi, &pdf);

        const float r0 = (p.ior - 1.0f) / (p.ior + 1.0f);
        const glm::vec3 f0_d = glm::min(glm::vec3(r0 * r0) * p.specular_color, glm::vec3(1.0f)) * p.specular;
        const float c_d = 1.0f - metallic, alpha = roughness * roughness;
        const GgxAlbedo e = ggx_albedo(wo.z, alpha);
        const glm::vec3 e_specular = (f0_d * (e.total - e.schlick) + p.specular * e.schlick) *
                                     (glm::vec3(1.0f) + f0_d * (1.0f / e.total - 1.0f));
        const glm::vec3 diffuse = c_d * p.base_color / kPi * (glm::vec3(1.0f) - e_specular);
        const glm::vec3 h = glm::normalize(wo + wi);
        const float t = h.z * h.z * (alpha * alpha - 1.0f) + 1.0f, d = alpha * alpha / (kPi * t * t);
        const float g2 = 1.0f / (1.0f + lambda(wo, alpha) + lambda(wi, alpha));
        const float c_oh = glm::dot(wo, h);
        const glm::vec3 f0 = metallic * p.base_color + c_d * f0_d, f90 = glm::vec3(metallic + c_d * p.specular);
        const glm::vec3 compensation = glm::vec3(1.0f) + f0 * (1.0f / e.total - 1.0f);
        const glm::vec3 fresnel = metallic * schlick(p.base_color, 1.0f, c_oh) + c_d * schlick(f0_d, p.specular, c_oh);
        const glm::vec3 expected = diffuse * wi.z + fresnel * compensation * d * g2 / (4.0f * wo.z);
        const float w_diffuse = luminance(diffuse) * kPi;
        const float w_glossy = luminance((f0 * (e.total - e.schlick) + f90 * e.schlick) * compensation);
        const float p_diffuse = w_diffuse / (w_diffuse + w_glossy), p_glossy = 1.0f - p_diffuse;
        const float expected_pdf = p_diffuse * wi.z / kPi + p_glossy * d / ((1.0f + lambda(wo, alpha)) * 4.0f * wo.z);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(f[c], expected[c], 1e-5f * expected[c] + 1e-7f) << "channel " << c;
        EXPECT_NEAR(pdf, expected_pdf, 1e-5f * expected_pdf);
      }
}

TEST(Bsdf, GgxDistributionIsNormalized) {
  for (float alpha : {0.05f, 0.3f, 1.0f}) {
    double sum = 0;
    const int n = 400000;
    for (int i = 0; i < n; ++i) {  // ∫ D(h) cos(theta_h) dω over the hemisphere, midpoint in cos theta
      double z = (i + 0.5) / n;
      glm::vec3 h(static_cast<float>(std::sqrt(1 - z * z)), 0.0f, static_cast<float>(z));
      sum += ggx_d(h, alpha) * z * (1.0 / n) * 2.0 * M_PI;
    }
    EXPECT_NEAR(sum, 1.0, 2e-3) << "alpha " << alpha;
  }
}

TEST(Bsdf, LambertAlbedoOneConservesEnergy) {
  Bsdf bsdf(lambert(glm::vec3(1.0f)), glm::vec3(0, 0, 1), glm::vec3(0, 0, 1), glm::normalize(glm::vec3(0.3f, 0.1f, 1.0f)), true);
  Rng rng(3, 0, 0);
  double sum = 0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    BsdfSample s;
    float u = rng.next_float();
    if (bsdf.sample(u, rng.next_2d(), &s)) sum += s.weight.g;
  }
  EXPECT_NEAR(sum / n, 1.0, 1e-4);  // cosine sampling of a Lambertian: every weight is exactly 1
}

TEST(Bsdf, SmoothGlassBranchesFollowFresnel) {
  BsdfParams glass;
  glass.metallic = 0.0f;
  glass.roughness = 0.0f;
  glass.transmission = 1.0f;
  glass.ior = 1.5f;
  for (bool front : {true, false}) {
    for (float cos_i : {1.0f, 0.7f, 0.3f}) {
      glm::vec3 wo(std::sqrt(1.0f - cos_i * cos_i), 0.0f, cos_i);
      glm::vec3 ng = front ? glm::vec3(0, 0, 1) : glm::vec3(0, 0, -1);  // exiting: wo is behind the face
      Bsdf bsdf(glass, ng, ng, wo, front);
      ASSERT_TRUE(bsdf.is_perfectly_specular());
      float fresnel = fresnel_dielectric(cos_i, front ? 1.5f : 1.0f / 1.5f);
      Rng rng(5, front, static_cast<uint64_t>(cos_i * 100));
      const int n = 50000;
      int reflected = 0;
      for (int i = 0; i < n; ++i) {
        BsdfSample s;
        float u = rng.next_float();
        ASSERT_TRUE(bsdf.sample(u, rng.next_2d(), &s));
        ASSERT_TRUE(s.delta);
        if (!s.transmitted) {
          ++reflected;
          EXPECT_NEAR(glm::dot(s.wi, wo), 2 * cos_i * cos_i - 1, 1e-4f);
        } else {
          // Snell: sin_t = sin_i / eta.
          float eta = front ? 1.5f : 1.0f / 1.5f;
          float sin_i = std::sqrt(1 - cos_i * cos_i);
          EXPECT_NEAR(std::sqrt(s.wi.x * s.wi.x + s.wi.y * s.wi.y), sin_i / eta, 1e-4f);
          EXPECT_LT(s.wi.z * wo.z, 0.0f);
        }
      }
      double p = fresnel, sd = std::sqrt(n * p * (1 - p)) + 1e-9;
      EXPECT_LT(std::abs(reflected - n * p) / sd, 4.0) << "front " << front << " cos " << cos_i;
    }
  }
  // Total internal reflection from inside at grazing angles.
  glm::vec3 wo(std::sin(1.2f), 0.0f, std::cos(1.2f));
  Bsdf inside(glass, glm::vec3(0, 0, -1), glm::vec3(0, 0, -1), wo, false);
  BsdfSample s;
  ASSERT_TRUE(inside.sample(0.5f, glm::vec2(0.99f, 0.5f), &s));
  EXPECT_FALSE(s.transmitted);
}

TEST(Bsdf, MaterialClassification) {
  EXPECT_TRUE(material_is_perfect_specular(make_mirror()));
  EXPECT_TRUE(material_is_perfect_mirror(make_mirror()));
  EXPECT_TRUE(material_is_perfect_specular(make_glass()));
  EXPECT_FALSE(material_is_perfect_mirror(make_glass()));
  Material frosted = make_glass();
  frosted.roughness = 0.3f;  // rough glass is not a specular chain's: its BSDF has no delta lobe
  EXPECT_FALSE(material_is_perfect_specular(frosted));
  EXPECT_FALSE(material_is_perfect_specular(make_conductor(glm::vec3(1), 0.2f)));
  EXPECT_FALSE(material_is_perfect_specular(make_diffuse(glm::vec3(0.5f))));
}

// What is perfectly specular: below the delta roughness the mirror and the glass are delta lobes;
// above it the rough glass samples non-delta directions on both sides, except through an interface
// without refraction (ior 1), which passes light straight through whatever its roughness.
TEST(Bsdf, DeltaLobesAreExactlyTheSmoothOnes) {
  const glm::vec3 n(0, 0, 1), wo = glm::normalize(glm::vec3(0.3f, 0.0f, 0.8f));
  struct Expect {
    BsdfParams params;
    bool perfectly_specular;
  };
  BsdfParams no_refraction = rough_glass(0.5f);
  no_refraction.ior = 1.0f;
  for (const Expect& c : {Expect{rough_glass(0.0f), true}, Expect{rough_glass(kDeltaRoughness * 1.1f), false},
                          Expect{rough_glass(0.5f), false}, Expect{no_refraction, true},
                          Expect{conductor(glm::vec3(1.0f), 0.0f), true}, Expect{conductor(glm::vec3(1.0f), 0.2f), false}}) {
    const Bsdf bsdf(c.params, n, n, wo, true);
    EXPECT_EQ(bsdf.is_perfectly_specular(), c.perfectly_specular) << "roughness " << c.params.roughness;
    Rng rng(17, 0, 0);
    int delta = 0, transmitted = 0;
    for (int i = 0; i < 2000; ++i) {
      BsdfSample s;
      const float u_lobe = rng.next_float();
      if (!bsdf.sample(u_lobe, rng.next_2d(), &s)) continue;
      delta += s.delta;
      transmitted += s.transmitted;
      EXPECT_EQ(s.delta, s.pdf == 0.0f);
    }
    EXPECT_EQ(delta > 0, c.perfectly_specular) << "roughness " << c.params.roughness;
    if (c.params.transmission > 0.0f) {
      EXPECT_GT(transmitted, 1000) << "roughness " << c.params.roughness;
    }
  }
}

// The directional albedo (mean of the sample weights) over stratified numbers: lobe_strata strata of
// the lobe choice times a grid x grid of the direction's, so that a 1 % test is not a 2-sigma one.
// Transmitted weights are multiplied by transmitted_scale (eta^2 counts energy, not radiance).
double stratified_albedo(const Bsdf& bsdf, int grid = 48, int lobe_strata = 16, float transmitted_scale = 1.0f) {
  const int kLobeStrata = lobe_strata;
  const int kGrid = grid;
  double sum = 0;
  for (int l = 0; l < kLobeStrata; ++l)
    for (int i = 0; i < kGrid; ++i)
      for (int j = 0; j < kGrid; ++j) {
        BsdfSample s;
        const glm::vec2 u((i + 0.5f) / kGrid, (j + 0.5f) / kGrid);
        if (bsdf.sample((l + 0.5f) / kLobeStrata, u, &s)) sum += luminance(s.weight) * (s.transmitted ? transmitted_scale : 1.0f);
      }
  return sum / (kLobeStrata * kGrid * kGrid);
}

// Turquin's compensation: a white rough metal and a white dielectric over a white Lambert reflect
// all the light at every view angle (directional albedo by sampling, weights f cos / pdf).
TEST(Bsdf, CompensatedWhiteLobesKeepAllTheEnergy) {
  for (float roughness : {0.5f, 0.7f, 1.0f})
    for (float metallic : {1.0f, 0.0f})
      for (float mu : {1.0f, 0.7f, 0.4f, 0.15f}) {
        const glm::vec3 n(0, 0, 1), wo(std::sqrt(1.0f - mu * mu), 0.0f, mu);
        const Bsdf bsdf(plastic(glm::vec3(1.0f), roughness, metallic), n, n, wo, true);
        const double albedo = stratified_albedo(bsdf);
        EXPECT_NEAR(albedo, 1.0, 0.01) << "roughness " << roughness << " metallic " << metallic << " mu " << mu;
      }
}

// nondelta_albedo is the directional albedo the lobes sample to: the mean sample weight f cos / pdf,
// for colored bases, metals, a rough coat and a sheen, at several view angles (luminance).
TEST(Bsdf, NondeltaAlbedoIsTheSampledDirectionalAlbedo) {
  const BsdfParams materials[] = {plastic(glm::vec3(0.2f, 0.4f, 0.6f), 0.5f), plastic(glm::vec3(0.05f), 0.3f),
                                  conductor(glm::vec3(1.0f, 0.78f, 0.34f), 0.4f),
                                  coated(plastic(glm::vec3(0.7f, 0.1f, 0.1f), 0.8f), 0.8f, 0.3f),
                                  sheened(plastic(glm::vec3(0.3f), 0.9f), glm::vec3(0.6f, 0.5f, 0.9f), 0.5f),
                                  // a low-roughness sheen over a black base
                                  sheened(plastic(glm::vec3(0.0f), 1.0f), glm::vec3(1.0f), 0.1f)};
  int index = 0;
  for (const BsdfParams& params : materials) {
    for (float mu : {1.0f, 0.6f, 0.2f, 0.15f}) {
      const glm::vec3 n(0, 0, 1), wo(std::sqrt(1.0f - mu * mu), 0.0f, mu);
      const Bsdf bsdf(params, n, n, wo, true);
      EXPECT_NEAR(luminance(bsdf.nondelta_albedo()), stratified_albedo(bsdf, 128), 0.01) << "material " << index << " mu " << mu;
    }
    ++index;
  }
  // Rough glass counts the energy it transmits: the weights times eta^2. Tinted (the transmission
  // is, the reflection not), both sides, alone and under diffuse and glossy lobes; more strata of
  // the lobe choice, which also picks the compensation lobe.
  struct Glass {
    BsdfParams params;
    bool front;
  };
  for (const Glass& g : {Glass{rough_glass(0.5f, glm::vec3(0.9f, 0.5f, 0.2f)), true},
                         Glass{rough_glass(0.5f, glm::vec3(0.9f, 0.5f, 0.2f)), false},
                         Glass{rough_glass(0.9f, glm::vec3(0.3f, 0.6f, 0.9f), 2.0f), false}, Glass{half_glass(), true}})
    for (float mu : {1.0f, 0.6f, 0.2f}) {
      const glm::vec3 n(0, 0, 1), wo(std::sqrt(1.0f - mu * mu), 0.0f, mu);
      const Bsdf bsdf(g.params, n, n, wo, g.front);
      const float eta = bsdf.eta();
      EXPECT_NEAR(luminance(bsdf.nondelta_albedo()), stratified_albedo(bsdf, 64, 64, eta * eta), 0.01)
          << "glass roughness " << g.params.roughness << " front " << g.front << " mu " << mu;
    }
  // A mirror has no non-delta lobe: nothing to demodulate by.
  const glm::vec3 n(0, 0, 1);
  EXPECT_EQ(Bsdf(conductor(glm::vec3(0.9f), 0.0f), n, n, n, true).nondelta_albedo(), glm::vec3(0.0f));
}

// The clearcoat over white bases keeps all the light: the coat reflects clearcoat E_coat(cos_o)
// (compensated), the base gets the rest. At several coat and base roughnesses, smooth coat included.
TEST(Bsdf, ClearcoatOverWhiteKeepsAllTheEnergy) {
  for (float coat_roughness : {0.0f, 0.3f, 1.0f})
    for (float metallic : {1.0f, 0.0f})
      for (float mu : {1.0f, 0.5f, 0.15f}) {
        const glm::vec3 n(0, 0, 1), wo(std::sqrt(1.0f - mu * mu), 0.0f, mu);
        const Bsdf bsdf(coated(plastic(glm::vec3(1.0f), 0.6f, metallic), 1.0f, coat_roughness), n, n, wo, true);
        EXPECT_NEAR(stratified_albedo(bsdf), 1.0, 0.01) << "coat roughness " << coat_roughness << " metallic " << metallic
                                                         << " mu " << mu;
      }
}

// KHR_materials_sheen's albedo scaling: a white sheen over a base that keeps all the light keeps
// all of it too (the sheen reflects E_sheen, the base 1 - E_sheen), at several sheen roughnesses.
// Not lower: at sheen roughness 0.1 the lobe is a thin band at grazing angles that a grid of
// cosine-sampled directions resolves badly (8 M random samples at cos_o 0.15 give 1.0000 +- 0.0006).
TEST(Bsdf, SheenOverWhiteKeepsAllTheEnergy) {
  for (float sheen_roughness : {0.3f, 0.5f, 1.0f})
    for (float metallic : {1.0f, 0.0f})
      for (float mu : {1.0f, 0.5f, 0.15f}) {
        const glm::vec3 n(0, 0, 1), wo(std::sqrt(1.0f - mu * mu), 0.0f, mu);
        const Bsdf bsdf(sheened(plastic(glm::vec3(1.0f), 0.6f, metallic), glm::vec3(1.0f), sheen_roughness), n, n, wo, true);
        EXPECT_NEAR(stratified_albedo(bsdf, 128), 1.0, 0.01) << "sheen roughness " << sheen_roughness << " metallic "
                                                         << metallic << " mu " << mu;
      }
}

// The coat has its own normal (its normal map): a coat over a black base is the coat lobe alone,
// and it is symmetric about the coat normal, not the base's.
TEST(Bsdf, ClearcoatReflectsAboutItsOwnNormal) {
  const glm::vec3 n(0, 0, 1), coat_n = glm::normalize(glm::vec3(0.3f, 0.0f, 1.0f));
  const glm::vec3 wo = glm::normalize(glm::vec3(-0.2f, 0.1f, 1.0f));
  BsdfParams black = plastic(glm::vec3(0.0f), 0.5f);
  black.specular = 0.0f;
  const Bsdf bsdf(coated(black, 1.0f, 0.2f), n, n, wo, true, coat_n);
  const glm::vec3 mirror = glm::reflect(-wo, coat_n), base_mirror = glm::reflect(-wo, n);
  EXPECT_GT(bsdf.eval(mirror).x / mirror.z, 10.0f * bsdf.eval(base_mirror).x / base_mirror.z);
  const float fresnel = 0.04f + 0.96f * std::pow(1.0f - glm::dot(wo, coat_n), 5.0f);
  const float alpha = 0.04f;  // 0.2^2
  const float lambda_o = ggx_lambda(glm::vec3(0, 0, glm::dot(wo, coat_n)), alpha);
  const float cos_o = glm::dot(wo, coat_n);
  // At the mirror direction h is the coat normal: F D(1) G2 / (4 cos_o cos_i) cos_i, times Turquin's factor.
  const float expected = fresnel * ggx_d(glm::vec3(0, 0, 1), alpha) / (1.0f + 2.0f * lambda_o) / (4.0f * cos_o) *
                         (1.0f + 0.04f * (1.0f / ggx_albedo(cos_o, alpha).total - 1.0f));
  EXPECT_NEAR(bsdf.eval(mirror).x, expected, 2e-3f * expected);
}

// Walter's BTDF obeys the reciprocity of refraction (Veach 1997, eq. 5.14): f(wo, wi) / eta_o^2 =
// f(wi, wo) / eta_i^2, eta the index on each direction's side: from inside it is ior^2 times the
// one from outside. Reflection on either side is symmetric. So is the compensation lobe, whose
// split between reflection and transmission is chosen for it: at roughness 0.9 it carries a large
// share, and at ior 2.2 (between the table's points) too.
TEST(Bsdf, RoughGlassIsReciprocal) {
  const glm::vec3 n(0, 0, 1);
  // Pairs a refracting microfacet connects (the inside directions on the far side of the normal).
  const glm::vec3 outside[] = {glm::normalize(glm::vec3(0.2f, 0.1f, 0.9f)), glm::normalize(glm::vec3(0.7f, 0.2f, 0.4f))};
  const glm::vec3 inside[] = {glm::normalize(glm::vec3(-0.3f, 0.0f, -0.8f)), glm::normalize(glm::vec3(-0.3f, -0.1f, -0.7f))};
  for (float roughness : {0.4f, 0.9f})
    for (float ior : {1.5f, 2.2f}) {
      SCOPED_TRACE(::testing::Message() << "roughness " << roughness << " ior " << ior);
      const BsdfParams glass = rough_glass(roughness, glm::vec3(1.0f), ior);
      for (glm::vec3 a : outside)
        for (glm::vec3 b : inside) {
          const float from_outside = Bsdf(glass, n, n, a, true).eval(b).x / std::abs(b.z);
          const float from_inside = Bsdf(glass, n, n, b, false).eval(a).x / std::abs(a.z);
          ASSERT_GT(from_outside, 0.0f);
          EXPECT_NEAR(from_inside, from_outside * ior * ior, 1e-4f * from_inside);
        }
      const glm::vec3 a = outside[0], c = outside[1];
      EXPECT_NEAR(Bsdf(glass, n, n, a, true).eval(c).x / c.z, Bsdf(glass, n, n, c, true).eval(a).x / a.z, 1e-5f);
      // Reflection inside (n flipped: the inside is the back side of the face).
      const glm::vec3 b = -inside[0], d = -inside[1];
      const float bd = Bsdf(glass, n, n, -b, false).eval(-d).x / d.z, db = Bsdf(glass, n, n, -d, false).eval(-b).x / b.z;
      ASSERT_GT(bd, 0.0f);
      EXPECT_NEAR(bd, db, 1e-4f * bd);
    }
}

// The energy the rough glass keeps (reflected + transmitted, the transmitted radiance weight
// undone by eta^2): all of it, from either side, at every roughness. Single scattering alone loses
// up to 58 % (inside at roughness 1, normal incidence); the compensation lobe sends on what it
// loses, and the tabulated albedo it takes the loss from errs by less than 1 % (glass_albedo_test.cpp).
TEST(Bsdf, RoughGlassKeepsItsEnergy) {
  for (float roughness : {0.1f, 0.3f, 0.6f, 1.0f})
    for (bool front : {true, false})
      for (float mu : {1.0f, 0.6f, 0.3f}) {
        const glm::vec3 n(0, 0, 1), wo(std::sqrt(1.0f - mu * mu), 0.0f, mu);
        const Bsdf bsdf(rough_glass(roughness), n, n, wo, front);
        const float eta = bsdf.eta();
        const double kept = stratified_albedo(bsdf, 96, 32, eta * eta);
        const float single = glass_albedo_quadrature(mu, std::max(roughness * roughness, kMinAlpha), eta, 256).total;
        std::printf("rough glass r %.1f %s mu %.1f: single scattering keeps %.4f, compensated %.4f\n", roughness,
                    front ? "outside" : "inside", mu, single, kept);
        EXPECT_NEAR(kept, 1.0, 0.01) << roughness << " " << front << " " << mu;
      }
}

// The classification the specular chains and the range buffer use (material_is_perfect_specular)
// and the BSDF's own (delta lobes only) agree on every material, rough glass included.
TEST(Bsdf, PerfectlySpecularMaterialsAreThoseWithOnlyDeltaLobes) {
  std::vector<Material> materials = {make_mirror(), make_glass(), make_conductor(glm::vec3(1.0f), 0.2f),
                                     make_diffuse(glm::vec3(0.5f))};
  Material frosted = make_glass();
  frosted.roughness = 0.3f;
  Material no_refraction = frosted;
  no_refraction.ior = 1.0f;
  Material nearly_metal = make_mirror();
  nearly_metal.metallic = 0.99f;
  Material nearly_glass = make_glass();
  nearly_glass.transmission = 0.99f;
  Material rough_coat_mirror = make_mirror();
  rough_coat_mirror.clearcoat = 1.0f;
  rough_coat_mirror.clearcoat_roughness = 0.3f;
  Material smooth_coat_glass = make_glass();
  smooth_coat_glass.clearcoat = 1.0f;
  Material velvet_mirror = make_mirror();
  velvet_mirror.sheen_color = glm::vec3(0.5f);
  materials.insert(materials.end(), {frosted, no_refraction, nearly_metal, nearly_glass, rough_coat_mirror, smooth_coat_glass,
                                     velvet_mirror});
  const Scene scene;
  const glm::vec3 n(0, 0, 1);
  for (size_t i = 0; i < materials.size(); ++i) {
    const BsdfParams p = eval_material(scene, materials[i], glm::vec2(0.0f), glm::vec2(0.0f), glm::vec4(1.0f));
    for (float mu : {1.0f, 0.5f, 0.1f})
      for (bool front : {true, false}) {
        const Bsdf bsdf(p, n, n, glm::vec3(std::sqrt(1.0f - mu * mu), 0.0f, mu), front);
        EXPECT_EQ(material_is_perfect_specular(materials[i]), bsdf.is_perfectly_specular()) << "material " << i;
      }
  }
}

// The integrator precomputes the BSDF of a material that eval_material_is_constant() calls
// constant. So every texture slot eval_material() reads must make it non-constant, and the ones
// it does not read must not: each slot gets a texture whose two texels differ in every channel,
// and eval_material at the two texels must differ exactly when the material is non-constant.
TEST(Bsdf, ConstantMaterialIsOneWhoseParametersDoNotVaryOverTheSurface) {
  Scene scene;
  Texture two_texels;
  two_texels.width = 2;
  two_texels.height = 1;
  two_texels.nearest = true;
  two_texels.texels = {glm::vec4(0.9f, 0.8f, 0.7f, 0.6f), glm::vec4(0.3f, 0.2f, 0.1f, 0.4f)};
  scene.textures = {two_texels};
  Material base = make_diffuse(glm::vec3(0.5f));
  base.metallic = 0.5f;
  base.roughness = 0.5f;
  base.transmission = 0.5f;
  base.specular = 0.5f;
  EXPECT_TRUE(eval_material_is_constant(base));
  TextureRef Material::*const slots[] = {&Material::base_color_texture, &Material::metallic_roughness_texture,
                                         &Material::normal_texture,     &Material::emissive_texture,
                                         &Material::transmission_texture, &Material::specular_texture,
                                         &Material::specular_color_texture, &Material::clearcoat_texture,
                                         &Material::clearcoat_roughness_texture, &Material::clearcoat_normal_texture,
                                         &Material::sheen_color_texture,        &Material::sheen_roughness_texture};
  const glm::vec2 left(0.25f, 0.5f), right(0.75f, 0.5f);
  base.clearcoat = 0.5f;
  base.clearcoat_roughness = 0.5f;
  base.sheen_color = glm::vec3(0.5f);
  base.sheen_roughness = 0.5f;
  auto same = [](const BsdfParams& a, const BsdfParams& b) {
    return a.base_color == b.base_color && a.metallic == b.metallic && a.roughness == b.roughness &&
           a.transmission == b.transmission && a.ior == b.ior && a.specular == b.specular &&
           a.specular_color == b.specular_color && a.clearcoat == b.clearcoat &&
           a.clearcoat_roughness == b.clearcoat_roughness && a.sheen_color == b.sheen_color &&
           a.sheen_roughness == b.sheen_roughness;
  };
  for (size_t i = 0; i < std::size(slots); ++i) {
    Material m = base;
    (m.*slots[i]).texture = 0;
    const bool varies = !same(eval_material(scene, m, left, left, glm::vec4(1.0f)),
                              eval_material(scene, m, right, right, glm::vec4(1.0f)));
    EXPECT_EQ(eval_material_is_constant(m), !varies) << "texture slot " << i;
  }
  // A constant material's parameters are its factors exactly: what the integrator precomputes.
  EXPECT_TRUE(same(eval_material(scene, base, left, right, glm::vec4(1.0f)),
                   eval_material(scene, base, right, left, glm::vec4(1.0f))));
}

}  // namespace
}  // namespace pxf
