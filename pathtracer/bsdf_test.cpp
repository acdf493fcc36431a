// BSDF sampling against its pdf (chi-square), sample weights against eval/pdf, glass branches.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "pathtracer/bsdf.h"
#include "pathtracer/rng.h"
#include "pathtracer/shapes.h"
#include "pathtracer/stat_tests.h"

namespace pxf {
namespace {

constexpr int kThetaBins = 16, kPhiBins = 32;
constexpr int kSamples = 200000;

struct Case {
  const char* name;
  BsdfParams params;
  float incident_degrees;
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

// Diffuse, glossy and smooth glass lobes at once (the glass one delta).
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
  };
  const double alpha = 0.01 / cases.size();  // Bonferroni
  for (const Case& c : cases) {
    float theta = glm::radians(c.incident_degrees);
    glm::vec3 wo(std::sin(theta), 0.0f, std::cos(theta));
    Bsdf bsdf(c.params, glm::vec3(0, 0, 1), glm::vec3(0, 0, 1), wo, true);
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
  // Schlick Fresnel at the half vector, and the lobe choice by the weights at wo.
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
        const glm::vec3 diffuse = c_d * p.base_color / kPi * (glm::vec3(1.0f) - schlick(f0_d, p.specular, wo.z));
        const glm::vec3 h = glm::normalize(wo + wi);
        const float t = h.z * h.z * (alpha * alpha - 1.0f) + 1.0f, d = alpha * alpha / (kPi * t * t);
        const float g2 = 1.0f / (1.0f + lambda(wo, alpha) + lambda(wi, alpha));
        const float c_oh = glm::dot(wo, h);
        const glm::vec3 fresnel = metallic * schlick(p.base_color, 1.0f, c_oh) + c_d * schlick(f0_d, p.specular, c_oh);
        const glm::vec3 expected = diffuse * wi.z + fresnel * d * g2 / (4.0f * wo.z);
        const float w_diffuse = luminance(diffuse) * kPi;
        const float w_glossy = luminance(metallic * schlick(p.base_color, 1.0f, wo.z) + c_d * schlick(f0_d, p.specular, wo.z));
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
  EXPECT_FALSE(material_is_perfect_specular(make_conductor(glm::vec3(1), 0.2f)));
  EXPECT_FALSE(material_is_perfect_specular(make_diffuse(glm::vec3(0.5f))));
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
                                         &Material::specular_color_texture};
  const glm::vec2 left(0.25f, 0.5f), right(0.75f, 0.5f);
  auto same = [](const BsdfParams& a, const BsdfParams& b) {
    return a.base_color == b.base_color && a.metallic == b.metallic && a.roughness == b.roughness &&
           a.transmission == b.transmission && a.ior == b.ior && a.specular == b.specular &&
           a.specular_color == b.specular_color;
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
