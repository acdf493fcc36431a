#include "pathtracer/gltf_images.h"
#include "pathtracer/texture.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace pxf {
namespace {

// 2x2 texture, top row first: a b / c d.
Texture two_by_two(Wrap wrap = Wrap::ClampToEdge) {
  Texture t;
  t.width = 2;
  t.height = 2;
  t.texels = {glm::vec4(0, 0, 0, 1), glm::vec4(1, 0, 0, 1), glm::vec4(0, 1, 0, 1), glm::vec4(0, 0, 1, 0)};
  t.wrap_s = t.wrap_t = wrap;
  return t;
}

void expect_vec4_near(glm::vec4 a, glm::vec4 b, float eps = 1e-6f) {
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(a[i], b[i], eps) << "component " << i;
}

TEST(TextureSample, BilinearExactValuesOn2x2) {
  Texture t = two_by_two();
  // Texel centers return the texel exactly.
  expect_vec4_near(sample_texture(t, {0.25f, 0.25f}), t.texels[0]);
  expect_vec4_near(sample_texture(t, {0.75f, 0.25f}), t.texels[1]);
  expect_vec4_near(sample_texture(t, {0.25f, 0.75f}), t.texels[2]);
  expect_vec4_near(sample_texture(t, {0.75f, 0.75f}), t.texels[3]);
  // The image center averages all four.
  expect_vec4_near(sample_texture(t, {0.5f, 0.5f}), (t.texels[0] + t.texels[1] + t.texels[2] + t.texels[3]) * 0.25f);
  // Halfway between the top texels, a quarter of the way down from their centers.
  glm::vec4 top = 0.5f * (t.texels[0] + t.texels[1]);
  glm::vec4 bottom = 0.5f * (t.texels[2] + t.texels[3]);
  expect_vec4_near(sample_texture(t, {0.5f, 0.375f}), glm::mix(top, bottom, 0.25f));
}

TEST(TextureSample, ClampToEdge) {
  Texture t = two_by_two(Wrap::ClampToEdge);
  expect_vec4_near(sample_texture(t, {-3.0f, 0.25f}), t.texels[0]);
  expect_vec4_near(sample_texture(t, {0.0f, 0.25f}), t.texels[0]);  // edge: no blending with the far side
  expect_vec4_near(sample_texture(t, {5.0f, 5.0f}), t.texels[3]);
}

TEST(TextureSample, RepeatWrapsAndBlendsAcrossTheSeam) {
  Texture t = two_by_two(Wrap::Repeat);
  expect_vec4_near(sample_texture(t, {1.25f, 0.25f}), t.texels[0]);
  expect_vec4_near(sample_texture(t, {-0.25f, 0.25f}), t.texels[1]);
  // u = 0 sits between texel 1 (wrapped from the left) and texel 0.
  expect_vec4_near(sample_texture(t, {0.0f, 0.25f}), 0.5f * (t.texels[0] + t.texels[1]));
}

TEST(TextureSample, MirroredRepeat) {
  Texture t = two_by_two(Wrap::MirroredRepeat);
  t.nearest = true;
  expect_vec4_near(sample_texture(t, {1.25f, 0.25f}), t.texels[1]);  // mirrored: 1.25 -> 0.75
  expect_vec4_near(sample_texture(t, {1.75f, 0.25f}), t.texels[0]);
  expect_vec4_near(sample_texture(t, {2.25f, 0.25f}), t.texels[0]);  // period 2
  expect_vec4_near(sample_texture(t, {-0.25f, 0.25f}), t.texels[0]);
  EXPECT_EQ(wrap_texel_index(-1, 4, Wrap::MirroredRepeat), 0);
  EXPECT_EQ(wrap_texel_index(4, 4, Wrap::MirroredRepeat), 3);
  EXPECT_EQ(wrap_texel_index(-1, 4, Wrap::Repeat), 3);
  EXPECT_EQ(wrap_texel_index(-1, 4, Wrap::ClampToEdge), 0);
}

TEST(TextureSample, NearestPicksTheTexelWithoutBlending) {
  Texture t = two_by_two();
  t.nearest = true;
  expect_vec4_near(sample_texture(t, {0.49f, 0.49f}), t.texels[0]);
  expect_vec4_near(sample_texture(t, {0.51f, 0.49f}), t.texels[1]);
}

TEST(TextureSample, NonFiniteOrHugeCoordinatesGiveFiniteValues) {
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  for (Wrap wrap : {Wrap::Repeat, Wrap::ClampToEdge, Wrap::MirroredRepeat})
    for (glm::vec2 uv : {glm::vec2(nan, 0.3f), glm::vec2(inf, -inf), glm::vec2(1e30f, -1e30f), glm::vec2(-1e9f, 3e8f)}) {
      glm::vec4 v = sample_texture(two_by_two(wrap), uv);
      for (int i = 0; i < 4; ++i) EXPECT_TRUE(std::isfinite(v[i]));
    }
  Texture empty;
  expect_vec4_near(sample_texture(empty, {0.5f, 0.5f}), glm::vec4(1.0f));
}

TEST(TextureSample, NonPowerOfTwoSize) {
  Texture t;
  t.width = 3;
  t.height = 1;
  t.texels = {glm::vec4(0.0f), glm::vec4(3.0f), glm::vec4(6.0f)};
  t.wrap_s = t.wrap_t = Wrap::ClampToEdge;
  EXPECT_NEAR(sample_texture(t, {0.5f, 0.5f}).x, 3.0f, 1e-5f);  // center of the middle texel
  EXPECT_NEAR(sample_texture(t, {1.0f / 3.0f, 0.5f}).x, 1.5f, 1e-5f);
}

TEST(TextureTransform, MatrixFollowsKhrTextureTransform) {
  // Offset only.
  glm::vec3 p = texture_transform_matrix({0.5f, 0.25f}, 0.0f, {1.0f, 1.0f}) * glm::vec3(0.1f, 0.2f, 1.0f);
  EXPECT_NEAR(p.x, 0.6f, 1e-6f);
  EXPECT_NEAR(p.y, 0.45f, 1e-6f);
  // Scale then rotation then offset. A quarter turn maps u = (1, 0) to (0, -1): the extension rotates
  // UVs counter-clockwise in its v-down space, as the Khronos sample viewer, three.js and Babylon do.
  glm::mat3 m = texture_transform_matrix({0.5f, 0.0f}, 1.5707963f, {2.0f, 3.0f});
  glm::vec3 q = m * glm::vec3(1.0f, 0.0f, 1.0f);
  EXPECT_NEAR(q.x, 0.5f, 1e-5f);
  EXPECT_NEAR(q.y, -2.0f, 1e-5f);
  glm::vec3 r = m * glm::vec3(0.0f, 1.0f, 1.0f);
  EXPECT_NEAR(r.x, 0.5f + 3.0f, 1e-5f);
  EXPECT_NEAR(r.y, 0.0f, 1e-5f);
}

TEST(TextureTransform, TextureUvPicksTheCoordinateSet) {
  TextureRef ref;
  ref.texture = 0;
  EXPECT_EQ(texture_uv(ref, {0.1f, 0.2f}, {0.7f, 0.8f}), glm::vec2(0.1f, 0.2f));
  ref.texcoord = 1;
  EXPECT_EQ(texture_uv(ref, {0.1f, 0.2f}, {0.7f, 0.8f}), glm::vec2(0.7f, 0.8f));
  ref.transform = texture_transform_matrix({1.0f, 0.0f}, 0.0f, {2.0f, 2.0f});
  glm::vec2 uv = texture_uv(ref, {0.1f, 0.2f}, {0.25f, 0.5f});
  EXPECT_NEAR(uv.x, 1.5f, 1e-6f);
  EXPECT_NEAR(uv.y, 1.0f, 1e-6f);
}

TEST(TextureEval, FallbackWhenUnsetOrOutOfRange) {
  Scene scene;
  scene.textures.push_back(two_by_two());
  TextureRef none;
  expect_vec4_near(eval_texture(scene, none, {0.25f, 0.25f}, {}, glm::vec4(0.5f)), glm::vec4(0.5f));
  TextureRef bad;
  bad.texture = 7;
  expect_vec4_near(eval_texture(scene, bad, {0.25f, 0.25f}, {}), glm::vec4(1.0f));
  TextureRef ok;
  ok.texture = 0;
  expect_vec4_near(eval_texture(scene, ok, {0.75f, 0.25f}, {}), scene.textures[0].texels[1]);
}

}  // namespace
}  // namespace pxf

// A glTF image holding Radiance data cut inside its run-length scanlines made stb loop forever
// (fuzz/crashers/gltf_scene/hang-truncated-hdr-texture-*): the texture is reported unusable instead.
TEST(GltfImageDecode, TruncatedRadianceDataFailsInsteadOfHanging) {
  const std::string header = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 8\n";
  std::string line = {2, 2, 0, 8};
  for (int c = 0; c < 4; ++c) line += std::string{char(128 + 8), char(100 + c)};
  const std::string whole = header + line + line;
  pxf::gltf::DecodedImage image;
  ASSERT_TRUE(pxf::gltf::decode_image(reinterpret_cast<const unsigned char*>(whole.data()), whole.size(), image))
      << image.failure;
  EXPECT_EQ(image.width, 8);
  EXPECT_EQ(image.height, 2);
  for (size_t cut : {header.size() + 6, header.size() + line.size(), whole.size() - 1}) {
    EXPECT_FALSE(pxf::gltf::decode_image(reinterpret_cast<const unsigned char*>(whole.data()), cut, image)) << cut;
    EXPECT_FALSE(image.failure.empty());
  }
}
