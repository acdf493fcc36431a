// The specular-glossiness → metallic-roughness conversion and its texture bake.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "image/image.h"
#include "scene/spec_gloss.h"
#include "scene/texture.h"

namespace pxf {
namespace {

TEST(SpecGloss, DielectricSpecularKeepsTheDiffuseColor) {
  const glm::vec4 diffuse(0.6f, 0.3f, 0.1f, 0.5f);
  MetalRough c = metal_rough_from_spec_gloss(diffuse, glm::vec3(0.04f), 0.8f);
  EXPECT_NEAR(c.metallic, 0.0f, 1e-4f);
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(c.base_color[i], diffuse[i], 1e-4f) << i;
  EXPECT_NEAR(c.roughness, 0.2f, 1e-6f);
  // Darker than the dielectric F0: still a dielectric.
  EXPECT_EQ(metal_rough_from_spec_gloss(diffuse, glm::vec3(0.01f), 0.0f).metallic, 0.0f);
}

TEST(SpecGloss, BrightSpecularOverBlackDiffuseIsAMetalOfTheSpecularColor) {
  const glm::vec3 specular(0.95f, 0.64f, 0.54f);  // copper-like F0
  MetalRough c = metal_rough_from_spec_gloss(glm::vec4(0, 0, 0, 1), specular, 1.0f);
  EXPECT_NEAR(c.metallic, 1.0f, 1e-4f);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(c.base_color[i], specular[i], 1e-3f) << i;
  EXPECT_EQ(c.base_color.a, 1.0f);
  EXPECT_EQ(c.roughness, 0.0f);
}

TEST(SpecGloss, MetallicGrowsWithTheSpecularBrightnessAndStaysInRange) {
  const glm::vec4 diffuse(0.5f, 0.5f, 0.5f, 1.0f);
  float previous = -1.0f;
  for (float s = 0.0f; s <= 1.0f; s += 0.05f) {
    MetalRough c = metal_rough_from_spec_gloss(diffuse, glm::vec3(s), 0.5f);
    EXPECT_GE(c.metallic, previous) << s;
    EXPECT_LE(c.metallic, 1.0f);
    for (int i = 0; i < 4; ++i) EXPECT_TRUE(c.base_color[i] >= 0.0f && c.base_color[i] <= 1.0f) << s;
    previous = c.metallic;
  }
  EXPECT_GT(previous, 0.9f);  // white specular: metal
}

TEST(SpecGloss, OutOfRangeAndNonFiniteInputsGiveValidOutput) {
  const float nan = std::nanf("");
  MetalRough c = metal_rough_from_spec_gloss(glm::vec4(nan, 2.0f, -1.0f, 7.0f), glm::vec3(nan, 5.0f, -3.0f), nan);
  EXPECT_TRUE(c.metallic >= 0.0f && c.metallic <= 1.0f);
  EXPECT_TRUE(c.roughness >= 0.0f && c.roughness <= 1.0f);
  for (int i = 0; i < 4; ++i) EXPECT_TRUE(c.base_color[i] >= 0.0f && c.base_color[i] <= 1.0f) << i;
}

Texture texture8(int w, int h, std::vector<unsigned char> codes, bool srgb) {
  Texture t;
  t.width = w;
  t.height = h;
  t.srgb = srgb;
  t.nearest = true;
  t.texels8 = std::make_shared<const std::vector<unsigned char>>(std::move(codes));
  return t;
}

TEST(SpecGloss, BakeConvertsEachTexelOfTheProductOfFactorsAndTextures) {
  // 2x1 diffuse (sRGB) and 2x1 specular-glossiness (sRGB specular, linear glossiness): texel 0 a
  // dielectric, texel 1 a metal.
  Texture diffuse = texture8(2, 1, {200, 100, 50, 255, 0, 0, 0, 128}, true);
  Texture spec = texture8(2, 1, {56, 56, 56, 200, 240, 200, 120, 255}, true);
  SpecGlossFactors f;
  f.diffuse = glm::vec4(1.0f, 0.8f, 1.0f, 1.0f);
  f.specular = glm::vec3(1.0f, 1.0f, 0.9f);
  f.glossiness = 0.5f;
  BakedSpecGloss out = bake_spec_gloss(&diffuse, &spec, f, 2, 1, diffuse);
  ASSERT_TRUE(out.base_color.valid() && out.metallic_roughness.valid());
  EXPECT_TRUE(out.base_color.srgb);
  EXPECT_FALSE(out.metallic_roughness.srgb);
  EXPECT_TRUE(out.base_color.nearest);
  for (size_t i = 0; i < 2; ++i) {
    MetalRough want = metal_rough_from_spec_gloss(f.diffuse * diffuse.texel(i), f.specular * glm::vec3(spec.texel(i)),
                                                  f.glossiness * spec.texel(i).a);
    glm::vec4 base = out.base_color.texel(i), mr = out.metallic_roughness.texel(i);
    // 8-bit storage: half a code, sRGB-encoded for the base color (steepest near black).
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(base[k], want.base_color[k], 0.01f) << i << " " << k;
    EXPECT_NEAR(base.a, want.base_color.a, 0.5f / 255 + 1e-6f) << i;
    EXPECT_NEAR(mr.g, want.roughness, 0.5f / 255 + 1e-6f) << i;
    EXPECT_NEAR(mr.b, want.metallic, 0.5f / 255 + 1e-6f) << i;
  }
  EXPECT_EQ(out.metallic_roughness.texel(0).b, 0.0f);  // the dielectric texel
  EXPECT_GT(out.metallic_roughness.texel(1).b, 0.95f);  // the metal texel
  EXPECT_NEAR(out.metallic_roughness.texel(0).g, 1.0f - 0.5f * 200 / 255.0f, 0.5f / 255 + 1e-6f);
}

TEST(SpecGloss, BakeWithoutTexturesUsesTheFactors) {
  Texture sampler;
  SpecGlossFactors f;
  f.diffuse = glm::vec4(0.2f, 0.4f, 0.6f, 1.0f);
  f.specular = glm::vec3(0.04f);
  f.glossiness = 0.25f;
  BakedSpecGloss out = bake_spec_gloss(nullptr, nullptr, f, 0, 0, sampler);
  ASSERT_EQ(out.base_color.texel_count(), 1u);
  EXPECT_NEAR(out.base_color.texel(0).b, 0.6f, 0.01f);
  EXPECT_NEAR(out.metallic_roughness.texel(0).g, 0.75f, 0.5f / 255 + 1e-6f);
}

}  // namespace
}  // namespace pxf
