#include "scene/gltf_images.h"
#include "scene/texture.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <vector>

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

// The bilinear lookup written out from its definition: the four texels around the coordinate,
// each wrapped on its own, read through Texture::texel. sample_texture's shared wrapping and
// direct storage reads must give the same floats, for both storages and every wrap mode.
glm::vec4 bilinear_by_definition(const Texture& t, glm::vec2 uv) {
  const float x = uv.x * t.width - 0.5f, y = uv.y * t.height - 0.5f;
  const float fx = std::floor(x), fy = std::floor(y);
  auto at = [&](int i, int j) {
    const int xi = wrap_texel_index(i, t.width, t.wrap_s), yi = wrap_texel_index(j, t.height, t.wrap_t);
    return t.texel(static_cast<size_t>(yi) * t.width + xi);
  };
  const int x0 = static_cast<int>(fx), y0 = static_cast<int>(fy);
  const glm::vec4 top = glm::mix(at(x0, y0), at(x0 + 1, y0), x - fx);
  const glm::vec4 bottom = glm::mix(at(x0, y0 + 1), at(x0 + 1, y0 + 1), x - fx);
  return glm::mix(top, bottom, y - fy);
}

TEST(TextureSample, BilinearMatchesTheDefinitionForEveryStorageAndWrap) {
  const int width = 5, height = 3;  // not powers of two; odd, so the seams fall between texels
  std::vector<unsigned char> codes(4 * width * height);
  for (size_t k = 0; k < codes.size(); ++k) codes[k] = static_cast<unsigned char>((k * 97 + 13) % 256);
  for (int storage = 0; storage < 3; ++storage) {  // float, 8-bit linear, 8-bit sRGB
    Texture t;
    t.width = width;
    t.height = height;
    if (storage == 0) {
      for (size_t k = 0; k < codes.size(); k += 4)
        t.texels.push_back(glm::vec4(codes[k], codes[k + 1], codes[k + 2], codes[k + 3]) / 255.0f);
    } else {
      t.texels8 = std::make_shared<const std::vector<unsigned char>>(codes);
      t.srgb = storage == 2;
    }
    for (Wrap wrap : {Wrap::Repeat, Wrap::ClampToEdge, Wrap::MirroredRepeat}) {
      t.wrap_s = wrap;
      t.wrap_t = wrap == Wrap::ClampToEdge ? Wrap::Repeat : wrap;  // mixed modes too
      // A grid across [-2.3, 2.3)^2 whose points land on, between and just beside texel centres
      // and the seams of the repeats.
      for (int i = 0; i < 47; ++i)
        for (int j = 0; j < 29; ++j) {
          const glm::vec2 uv(-2.3f + 0.1f * i, -2.3f + 0.16f * j);
          const glm::vec4 got = sample_texture(t, uv), want = bilinear_by_definition(t, uv);
          for (int c = 0; c < 4; ++c)
            ASSERT_EQ(got[c], want[c]) << "storage " << storage << " wrap " << static_cast<int>(wrap) << " uv "
                                       << uv.x << ", " << uv.y << " channel " << c;
        }
    }
  }
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

// --- mip chains and footprints ---------------------------------------------------------------

// A width x height float texture whose texel (x, y) is value(x, y).
template <typename Value>
Texture float_texture(int width, int height, const Value& value) {
  Texture t;
  t.width = width;
  t.height = height;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) t.texels.push_back(value(x, y));
  return t;
}

TEST(TextureMips, EachLevelIsTheBoxMeanOfTheOneBefore) {
  std::vector<Texture> textures = {float_texture(4, 2, [](int x, int y) { return glm::vec4(x, y, x * y, 1); })};
  build_texture_mips(textures);
  const Texture& t = textures[0];
  ASSERT_TRUE(t.mips);
  ASSERT_EQ(t.mips->size(), 2u);  // 2x1, 1x1
  const TextureLevel& one = (*t.mips)[0];
  EXPECT_EQ(one.width, 2);
  EXPECT_EQ(one.height, 1);
  expect_vec4_near(one.texels[0], glm::vec4(0.5f, 0.5f, 0.25f, 1.0f));  // x 0,1 over y 0,1
  expect_vec4_near(one.texels[1], glm::vec4(2.5f, 0.5f, 1.25f, 1.0f));
  expect_vec4_near((*t.mips)[1].texels[0], glm::vec4(1.5f, 0.5f, 0.75f, 1.0f));
  EXPECT_EQ(t.memory_bytes(), (8u + 2u + 1u) * sizeof(glm::vec4));
}

TEST(TextureMips, OddSizesHalveDownToOneTexel) {
  std::vector<Texture> textures = {float_texture(7, 5, [](int, int) { return glm::vec4(0.25f); })};
  build_texture_mips(textures);
  const std::vector<TextureLevel>& chain = *textures[0].mips;
  ASSERT_EQ(chain.size(), 2u);
  EXPECT_EQ(chain[0].width, 3);
  EXPECT_EQ(chain[0].height, 2);
  EXPECT_EQ(chain[1].width, 1);
  EXPECT_EQ(chain[1].height, 1);
  for (const TextureLevel& level : chain)
    for (const glm::vec4& texel : level.texels) EXPECT_EQ(texel, glm::vec4(0.25f));  // a constant stays exact
}

// 8-bit sRGB texels are averaged in linear light and re-encoded: black and white give the code of
// linear 0.5 (188), not the mean code (128). Alpha and linear textures average their codes.
TEST(TextureMips, EightBitLevelsAverageInLinearLight) {
  auto codes = std::make_shared<const std::vector<unsigned char>>(
      std::vector<unsigned char>{0, 0, 0, 0, 255, 255, 255, 255, 0, 0, 0, 0, 255, 255, 255, 255});
  std::vector<Texture> textures(3);
  for (Texture& t : textures) {
    t.width = 2;
    t.height = 2;
    t.texels8 = codes;
  }
  textures[0].srgb = textures[1].srgb = true;
  build_texture_mips(textures);
  const TextureLevel& srgb = (*textures[0].mips)[0];
  ASSERT_EQ(srgb.texels8.size(), 4u);
  EXPECT_EQ(srgb.texels8[0], 188);
  // Linear 0.5 lies halfway between codes 127 and 128.
  EXPECT_NEAR(srgb.texels8[3], 127.5, 0.5);  // alpha: linear
  EXPECT_NEAR((*textures[2].mips)[0].texels8[0], 127.5, 0.5);
  // Textures with the same codes and encoding share one chain; another encoding has its own.
  EXPECT_EQ(textures[0].mips, textures[1].mips);
  EXPECT_NE(textures[0].mips, textures[2].mips);
  EXPECT_NEAR(sample_texture(textures[0], {0.3f, 0.7f}, 1.0f).r, 0.5f, 3e-3f);  // the 1x1 level
}

TEST(TextureMips, FootprintPicksTheLevelWhoseTexelsFitInIt) {
  std::vector<Texture> textures = {float_texture(64, 32, [](int x, int y) { return glm::vec4(x % 2, y % 2, 0, 1); })};
  const Texture bare = textures[0];
  build_texture_mips(textures);
  const Texture& t = textures[0];  // levels 1..6 (64 wide down to 1)
  EXPECT_EQ(texture_level(t, 0.0f), 0);
  EXPECT_EQ(texture_level(t, 1.9f / 64), 0);
  EXPECT_EQ(texture_level(t, 2.0f / 64), 1);
  EXPECT_EQ(texture_level(t, 5.0f / 64), 2);
  EXPECT_EQ(texture_level(t, 1000.0f), 6);
  EXPECT_EQ(texture_level(t, std::numeric_limits<float>::infinity()), 6);
  EXPECT_EQ(texture_level(t, std::numeric_limits<float>::quiet_NaN()), 0);
  EXPECT_EQ(texture_level(t, -1.0f), 0);
  EXPECT_EQ(texture_level(bare, 1.0f), 0);  // no chain: level 0
  // No footprint reads level 0, bit for bit; a footprint of two texels reads the 2x2 means.
  for (glm::vec2 uv : {glm::vec2(0.13f, 0.71f), glm::vec2(0.5f, 0.5f), glm::vec2(-2.3f, 7.9f)}) {
    const glm::vec4 fine = sample_texture(t, uv);
    EXPECT_EQ(sample_texture(t, uv, 0.0f), fine);
    EXPECT_EQ(sample_texture(bare, uv, 1.0f), fine);
    expect_vec4_near(sample_texture(t, uv, 2.0f / 64), glm::vec4(0.5f, 0.5f, 0.0f, 1.0f));
  }
}

// KHR_texture_transform scales the footprint with the uvs: a texture tiled twice as often reads
// the level one coarser.
TEST(TextureMips, TransformScalesTheFootprint) {
  Scene scene;
  scene.textures = {float_texture(64, 64, [](int x, int y) { return glm::vec4(static_cast<float>((x / 2 + y / 2) % 2)); })};
  build_texture_mips(scene.textures);
  TextureRef ref;
  ref.texture = 0;
  const glm::vec2 uv(0.3f, 0.6f);
  const float width = 2.0f / 64;  // level 1: 2x2 means of 2x2 cells, still the checker
  EXPECT_EQ(eval_texture(scene, ref, uv, uv, glm::vec4(1.0f), width), sample_texture(scene.textures[0], uv, width));
  ref.transform = texture_transform_matrix(glm::vec2(0.0f), 0.0f, glm::vec2(2.0f));
  const glm::vec2 scaled = texture_uv(ref, uv, uv);
  EXPECT_EQ(eval_texture(scene, ref, uv, uv, glm::vec4(1.0f), width), sample_texture(scene.textures[0], scaled, 2 * width));
  EXPECT_NEAR(eval_texture(scene, ref, uv, uv, glm::vec4(1.0f), width).r, 0.5f, 1e-6f);  // level 2: grey
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
