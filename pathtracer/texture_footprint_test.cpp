// Texture footprints (PathState::cone_width, SurfacePoint::texture_footprint): the first vertex
// reads the finest level, deeper vertices after a rough bounce read coarser ones, a constant
// texture's chain changes nothing, and a high-contrast checker agrees with level-0 look-ups
// within noise (block Z-test).
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "pathtracer/pathtracer.h"
#include "scene/texture.h"
#include "testing/block_z_test.h"
#include "testing/shapes.h"

namespace pxf {
namespace {

constexpr int kWidth = 32, kHeight = 24;

// Inside a closed 2 m box whose walls carry texture 0 (uv 0..1 a face) under base colour 0.8, lit
// by an emitter under the ceiling; the camera looks at a wall. Most light reaches the camera after
// bounces off the textured walls.
Scene textured_box(const Texture& texture) {
  Scene scene;
  Material walls = make_diffuse(glm::vec3(0.8f));
  walls.base_color_texture.texture = 0;
  scene.materials = {walls, make_emitter(glm::vec3(8.0f))};
  scene.textures = {texture};
  scene.meshes.push_back(make_box(glm::vec3(-1.0f), glm::vec3(1.0f), 0));
  scene.meshes.push_back(make_quad(glm::vec3(-0.3f, 0.99f, -0.3f), glm::vec3(0.6f, 0, 0), glm::vec3(0, 0, 0.6f), 1));
  scene.camera = look_at_camera(glm::vec3(0.0f, 0.0f, 0.9f), glm::vec3(0.0f, 0.0f, -1.0f), glm::vec3(0, 1, 0), 1.2f);
  return scene;
}

Texture constant_texture(int size, glm::vec4 value) {
  Texture t;
  t.width = t.height = size;
  t.texels.assign(static_cast<size_t>(size) * size, value);
  return t;
}

// Levels 1, 2, ... of a size x size texture, each holding `value` everywhere (whatever level 0 holds).
std::shared_ptr<const std::vector<TextureLevel>> constant_levels(int size, glm::vec4 value) {
  auto levels = std::make_shared<std::vector<TextureLevel>>();
  for (int width = size / 2; width >= 1; width /= 2) {
    TextureLevel level;
    level.width = level.height = width;
    level.texels.assign(static_cast<size_t>(width) * width, value);
    levels->push_back(level);
  }
  return levels;
}

TraceParams params_with_seed(uint64_t seed) {
  TraceParams params;
  params.seed = seed;
  params.threads = 2;
  return params;
}

const Accumulation& render(ProgressiveRenderer& renderer, int frames) {
  for (int i = 0; i < frames; ++i) renderer.add_frame();
  return renderer.accumulation();
}

glm::dvec3 mean_radiance(const Accumulation& acc) {
  glm::dvec3 sum(0.0);
  for (size_t p = 0; p < acc.lv_mean.size(); ++p) sum += glm::dvec3(acc.lv_mean[p] + acc.hv_mean[p]);
  return sum / static_cast<double>(acc.lv_mean.size());
}

// White at level 0, red at every coarser level: the camera's first surface must stay white (its
// albedo), while the light that bounced off the walls before reaching it turns red.
TEST(TextureFootprint, FirstVertexReadsLevelZeroDeeperVerticesCoarserLevels) {
  Texture texture = constant_texture(64, glm::vec4(1.0f));
  texture.mips = constant_levels(64, glm::vec4(1.0f, 0.1f, 0.1f, 1.0f));
  const Scene scene = textured_box(texture);
  ProgressiveRenderer renderer(scene, params_with_seed(3), kWidth, kHeight);
  const Accumulation& acc = render(renderer, 16);
  for (size_t p = 0; p < acc.albedo_mean.size(); ++p) ASSERT_NEAR(acc.albedo_mean[p].g, 0.8f, 1e-5f) << "pixel " << p;
  const glm::dvec3 red = mean_radiance(acc);
  // Without the chain the walls are white at every vertex.
  Scene plain = scene;
  plain.textures[0].mips.reset();
  ProgressiveRenderer white(plain, params_with_seed(3), kWidth, kHeight);
  const glm::dvec3 grey = mean_radiance(render(white, 16));
  std::printf("mean radiance with red levels %.4f %.4f, without %.4f %.4f (R, G)\n", red.r, red.g, grey.r, grey.g);
  EXPECT_NEAR(grey.r / grey.g, 1.0, 1e-3);
  EXPECT_GT(red.r / red.g, 1.5);
}

// A constant texture's levels hold its value exactly (values whose sums of four are exact in
// float), so the footprints change no sample.
TEST(TextureFootprint, ConstantTextureChainChangesNothing) {
  Scene with_chain = textured_box(constant_texture(64, glm::vec4(0.5f, 0.625f, 0.75f, 1.0f)));
  build_texture_mips(with_chain.textures);
  ASSERT_TRUE(with_chain.textures[0].mips);
  Scene without = with_chain;
  without.textures[0].mips.reset();
  ProgressiveRenderer a(with_chain, params_with_seed(5), kWidth, kHeight), b(without, params_with_seed(5), kWidth, kHeight);
  const Accumulation &x = render(a, 4), &y = render(b, 4);
  EXPECT_EQ(x.lv_mean, y.lv_mean);
  EXPECT_EQ(x.hv_mean, y.hv_mean);
}

// A normal map reads level 0 at every vertex: its coarser levels (here tilted 45 degrees, where
// level 0 is flat) change nothing.
TEST(TextureFootprint, NormalMapsReadLevelZeroAtEveryVertex) {
  Scene flat = textured_box(constant_texture(64, glm::vec4(1.0f)));
  flat.textures.push_back(constant_texture(64, glm::vec4(0.5f, 0.5f, 1.0f, 1.0f)));
  flat.materials[0].normal_texture.texture = 1;
  for (Mesh& mesh : flat.meshes) mesh.tangents.assign(mesh.positions.size(), glm::vec4(0.0f));
  for (const Mesh& mesh : flat.meshes) ASSERT_EQ(mesh.normals.size(), mesh.positions.size());
  for (Mesh& mesh : flat.meshes)
    for (size_t i = 0; i < mesh.normals.size(); ++i) {  // any unit tangent in the face's plane
      const glm::vec3 n = mesh.normals[i];
      const glm::vec3 t = glm::normalize(glm::cross(n, std::abs(n.x) < 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0)));
      mesh.tangents[i] = glm::vec4(t, 1.0f);
    }
  Scene tilted = flat;
  tilted.textures[1].mips = constant_levels(64, glm::vec4(0.85f, 0.5f, 0.85f, 1.0f));
  ProgressiveRenderer a(flat, params_with_seed(9), kWidth, kHeight), b(tilted, params_with_seed(9), kWidth, kHeight);
  const Accumulation &x = render(a, 4), &y = render(b, 4);
  EXPECT_EQ(x.lv_mean, y.lv_mean);
  EXPECT_EQ(x.hv_mean, y.hv_mean);
}

// Walls of 0.95 / 0.05 checker cells one texel wide: the deep vertices read levels where the
// cells blur to grey, and the image still agrees with the render that reads level 0 everywhere
// (another seed), block by block and over the image: the light a vertex gathers averages over
// far more of the wall than a footprint covers.
TEST(TextureFootprint, CheckerWallsAgreeWithLevelZeroLookUps) {
  Texture checker = constant_texture(64, glm::vec4(0.0f));
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) checker.texels[static_cast<size_t>(y) * 64 + x] = glm::vec4((x + y) % 2 ? 0.95f : 0.05f);
  Scene with_chain = textured_box(checker);
  build_texture_mips(with_chain.textures);
  Scene without = with_chain;
  without.textures[0].mips.reset();
  ProgressiveRenderer a(with_chain, params_with_seed(7), kWidth, kHeight), b(without, params_with_seed(8), kWidth, kHeight);
  const BlockComparison c = compare_blocks(render(a, 512), render(b, 512), 4, "footprints vs level 0");
  EXPECT_LT(c.worst_z, 4.5);
  EXPECT_LE(c.beyond3, 2);
  EXPECT_LT(std::abs(c.image_z), 4.0);
}

}  // namespace
}  // namespace pxf
