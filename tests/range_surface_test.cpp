// The range pass's surface buffer against the path tracer: on a normal-mapped plane with a
// roughness texture, the shading normal and roughness the raster pass writes are the ones the path
// tracer shades with (EmbreeScene::surface_point, eval_material) at the same camera rays.
#include <gtest/gtest.h>

#include <cmath>
#include "gl/range_pass.h"
#include "gl/test_util.h"
#include "pathtracer/bsdf.h"
#include "pathtracer/embree_scene.h"
#include "scene/camera.h"

namespace pxf {
namespace {

constexpr int W = 48, H = 32;
constexpr int kTexels = 16;

// A plane z = -2 filling the view, its normal `facing` (+1: toward the camera at the origin), UVs
// a quarter of the position so the textures repeat across the view; a tangent-space normal map of
// bumps in both directions and a roughness ramp in the metallic-roughness texture's G.
Scene normal_mapped_plane(float facing, bool double_sided) {
  Scene scene;
  Mesh m;
  m.positions = {{-10, -10, -2}, {10, -10, -2}, {10, 10, -2}, {-10, 10, -2}};
  m.normals.assign(4, glm::vec3(0, 0, facing));
  m.tangents.assign(4, glm::vec4(1, 0, 0, 1));
  for (const glm::vec3& p : m.positions) m.uv0.push_back(glm::vec2(p.x, p.y) * 0.25f);
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  m.material = 0;
  scene.meshes.push_back(m);
  Texture normal_map, roughness_map;
  for (Texture* t : {&normal_map, &roughness_map}) {
    t->width = t->height = kTexels;
    t->texels.resize(kTexels * kTexels);
  }
  const float two_pi = 6.28318530718f;
  for (int j = 0; j < kTexels; ++j)
    for (int i = 0; i < kTexels; ++i) {
      const glm::vec3 n = glm::normalize(glm::vec3(0.5f * std::sin(two_pi * i / kTexels),
                                                   0.4f * std::cos(two_pi * j / kTexels), 1.0f));
      normal_map.texels[j * kTexels + i] = glm::vec4(n * 0.5f + 0.5f, 1.0f);
      roughness_map.texels[j * kTexels + i] = glm::vec4(0.0f, 0.2f + 0.6f * i / (kTexels - 1), 0.0f, 1.0f);
    }
  scene.textures = {normal_map, roughness_map};
  Material material;
  material.base_color = glm::vec4(0.6f, 0.5f, 0.4f, 1.0f);
  material.metallic = 0.0f;
  material.roughness = 0.9f;
  material.normal_texture.texture = 0;
  material.normal_scale = 0.8f;
  material.metallic_roughness_texture.texture = 1;
  material.double_sided = double_sided;
  scene.materials.push_back(material);
  return scene;
}

void expect_surface_matches_path_tracer(const Scene& scene) {
  test::osmesa_context();
  RangePass range(W, H);
  range.set_settings(RangeSettings{1, 1, 0.0f});  // one frame at raster_jitter(0): the pixel centres
  range.set_scene(scene);
  while (!range.converged()) range.step();
  const Image surface = range.surface_image();
  EmbreeScene geometry(scene);
  const glm::vec2 jitter = raster_jitter(0);
  int compared = 0;
  for (glm::ivec2 p : {glm::ivec2(3, 4), glm::ivec2(11, 27), glm::ivec2(24, 16), glm::ivec2(37, 9), glm::ivec2(45, 30)}) {
    SCOPED_TRACE(testing::Message() << "pixel " << p.x << "," << p.y);
    const Ray ray = camera_ray(Camera{}, W, H, p.x + jitter.x, p.y + jitter.y);
    const Hit hit = geometry.intersect(ray);
    ASSERT_TRUE(hit.valid());
    const SurfacePoint sp = geometry.surface_point(hit, ray);
    const Material& material = *sp.material;
    const BsdfParams params = eval_material(scene, material, sp.uv0, sp.uv1, sp.color);
    glm::vec3 expected = sp.shading_normal;
    if (material.double_sided && glm::dot(sp.vertex_normal, -ray.direction) < 0.0f) expected = -expected;
    // The normal map bends the normal visibly away from the vertex normal somewhere.
    compared += std::abs(glm::dot(expected, sp.vertex_normal)) < 0.99f;
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(surface.at(p.x, p.y, c), expected[c], 3e-3f) << "normal " << c;
    EXPECT_NEAR(surface.at(p.x, p.y, 3), params.roughness, 3e-3f) << "roughness";
  }
  EXPECT_GE(compared, 3);
}

TEST(RangeSurface, NormalMappedPlaneMatchesThePathTracersShadingNormal) {
  expect_surface_matches_path_tracer(normal_mapped_plane(1.0f, false));
}

TEST(RangeSurface, DoubleSidedBackFaceIsFlippedTowardTheViewer) {
  expect_surface_matches_path_tracer(normal_mapped_plane(-1.0f, true));
}

TEST(RangeSurface, EnvironmentHasNoNormal) {
  test::osmesa_context();
  Scene scene = normal_mapped_plane(1.0f, false);
  for (glm::vec3& p : scene.meshes[0].positions) p.x = std::min(p.x, 0.0f);  // the left half only
  RangePass range(W, H);
  range.set_scene(scene);
  while (!range.converged()) range.step();
  const Image surface = range.surface_image();
  for (int c = 0; c < 4; ++c) EXPECT_EQ(surface.at(W - 2, H / 2, c), 0.0f);
  EXPECT_GT(surface.at(2, H / 2, 2), 0.5f);
}

}  // namespace
}  // namespace pxf
