// Range pass: a quad of known albedo facing the camera gives range color = range_shading(...) and
// depth = distance along the camera ray; jitter accumulation converges; specular overrides apply.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include "gl/pass_params.h"
#include "gl/range_pass.h"
#include "gl/test_util.h"
#include "scene/camera.h"
#include "scene/texture.h"

namespace pxf {
namespace {

constexpr int W = 48, H = 32;
const glm::vec3 kAlbedo(0.5f, 0.25f, 0.125f);

// A quad in the plane z = -2 (camera at the origin looking down -Z), normal +Z toward the camera.
Scene quad_scene(float x0, float x1, float y0, float y1, Material material = {}) {
  Scene scene;
  Mesh m;
  m.positions = {{x0, y0, -2}, {x1, y0, -2}, {x1, y1, -2}, {x0, y1, -2}};
  m.normals.assign(4, glm::vec3(0, 0, 1));
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  m.material = 0;
  scene.meshes.push_back(m);
  material.base_color = glm::vec4(kAlbedo, 1.0f);
  material.metallic = material.metallic == 1.0f ? 0.0f : material.metallic;
  scene.materials.push_back(material);
  return scene;
}

// Expected range color and distance at pixel (x, y) after `frames` jittered frames: the average
// over the rays through (x, y) + raster_jitter(k), k < frames (0: the pixel center only).
void expected_at(int x, int y, glm::vec3& color, float& distance, int frames = 0) {
  color = glm::vec3(0.0f);
  distance = 0.0f;
  for (int k = 0; k < std::max(frames, 1); ++k) {
    glm::vec2 j = frames > 0 ? raster_jitter(k) : glm::vec2(0.5f);
    Ray ray = camera_ray(Camera{}, W, H, x + j.x, y + j.y);
    distance += -2.0f / ray.direction.z;
    color += range_shading(kAlbedo, glm::vec3(0, 0, 1), -ray.direction);
  }
  color /= float(std::max(frames, 1));
  distance /= float(std::max(frames, 1));
}

void run_to_convergence(RangePass& range, const RangePass::ChainTracer& tracer = {}) {
  for (int i = 0; i < 100 && !range.converged(); ++i) range.step(tracer);
  ASSERT_TRUE(range.converged());
}

TEST(RangePass, FullScreenQuadGivesAlbedoShadingAndDistance) {
  test::osmesa_context();
  RangePass range(W, H);
  range.set_scene(quad_scene(-10, 10, -10, 10));
  run_to_convergence(range);
  EXPECT_LE(range.frames(), RangeSettings{}.max_frames);
  std::printf("range pass converged after %d frames (mean change %g)\n", range.frames(), range.last_change());
  Image color = range.range_color_image(), depth = range.depth_image();
  EXPECT_EQ(count_nonfinite(color), 0u);
  EXPECT_EQ(count_nonfinite(depth), 0u);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      glm::vec3 c;
      float d;
      expected_at(x, y, c, d, range.frames());
      for (int i = 0; i < 3; ++i) ASSERT_NEAR(color.at(x, y, i), c[i], 1e-4f * c[i]) << x << "," << y;
      ASSERT_NEAR(depth.at(x, y, 0), d, 1e-4f * d) << x << "," << y;
    }
}

// An orthographic camera: parallel rays from the camera's plane. A quad tilted about Y (z = -2 -
// 0.3 x) makes the distance vary across the image; the raster pass must give each pixel the
// traced ray's length to the plane and its shading, as for a perspective camera.
TEST(RangePass, OrthographicCameraGivesTheTracedRaysDistanceAndShading) {
  test::osmesa_context();
  Scene scene = quad_scene(-10, 10, -10, 10);
  for (glm::vec3& p : scene.meshes[0].positions) p.z = -2.0f - 0.3f * p.x;
  const glm::vec3 normal = glm::normalize(glm::vec3(0.3f, 0.0f, 1.0f));
  scene.meshes[0].normals.assign(4, normal);
  scene.camera.orthographic = true;
  scene.camera.ymag = 1.5f;
  scene.camera.znear = 0.0f;
  RangePass range(W, H);
  range.set_scene(scene);
  run_to_convergence(range);
  Image color = range.range_color_image(), depth = range.depth_image();
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      glm::vec3 c(0.0f);
      float d = 0.0f;
      for (int k = 0; k < range.frames(); ++k) {
        glm::vec2 j = raster_jitter(k);
        Ray ray = camera_ray(scene.camera, W, H, x + j.x, y + j.y);
        d += 2.0f + 0.3f * ray.origin.x;  // the ray (o.x, o.y, -t) meets z = -2 - 0.3 x at this t
        c += range_shading(kAlbedo, normal, -ray.direction);
      }
      c /= float(range.frames());
      d /= float(range.frames());
      for (int i = 0; i < 3; ++i) ASSERT_NEAR(color.at(x, y, i), c[i], 1e-4f * c[i]) << x << "," << y;
      ASSERT_NEAR(depth.at(x, y, 0), d, 1e-4f * d) << x << "," << y;
    }
}

TEST(RangePass, TopHalfQuadIsInTopRowsWithAntialiasedEdge) {
  test::osmesa_context();
  RangePass range(W, H);
  // The quad covers world y in [0, 10]: the top half of the image. Its lower edge crosses the
  // middle of row H/2 - 1 ... exactly the boundary between rows H/2 - 1 and H/2.
  range.set_scene(quad_scene(-10, 10, 0, 10));
  run_to_convergence(range);
  Image color = range.range_color_image(), depth = range.depth_image();
  for (int x = 0; x < W; ++x) {
    EXPECT_GT(color.at(x, 0, 0), 0.3f);
    EXPECT_LT(depth.at(x, 0, 0), 10.0f);
    EXPECT_EQ(color.at(x, H - 1, 0), 0.0f);                 // background: range color 0
    EXPECT_EQ(depth.at(x, H - 1, 0), kBackgroundDepth);     // ... and the background distance
  }
  EXPECT_EQ(count_nonfinite(color), 0u);
}

TEST(RangePass, EdgeThroughPixelsIsAveragedAndConverges) {
  test::osmesa_context();
  RangePass range(W, H);
  // Vertical edge through the middle of column 30: coverage there converges to about 1/2.
  Ray r = camera_ray(Camera{}, W, H, 30.5f, H / 2.0f);
  float edge_x = r.direction.x * (-2.0f / r.direction.z);
  range.set_scene(quad_scene(-10, edge_x, -10, 10));
  run_to_convergence(range);
  Image color = range.range_color_image();
  glm::vec3 c;
  float d;
  expected_at(30, H / 2, c, d);
  float coverage = color.at(30, H / 2, 0) / c.x;
  EXPECT_NEAR(coverage, 0.5f, 0.1f);
  EXPECT_NEAR(color.at(29, H / 2, 0) / c.x, 1.0f, 1e-2f);
  EXPECT_EQ(color.at(31, H / 2, 0), 0.0f);
  int frames = range.frames();
  EXPECT_GE(frames, RangeSettings{}.min_frames);
  // Converged: no more work; the same camera keeps it; a new camera restarts it.
  EXPECT_FALSE(range.step());
  range.set_camera(Camera{});
  EXPECT_TRUE(range.converged());
  Camera moved;
  moved.camera_to_world[3] = glm::vec4(0.1f, 0, 0, 1);
  range.set_camera(moved);
  EXPECT_FALSE(range.converged());
  EXPECT_TRUE(range.step());
  EXPECT_EQ(range.frames(), 1);
}

TEST(RangePass, AlphaMaskCutsOut) {
  test::osmesa_context();
  Material m;
  m.alpha_mode = AlphaMode::Mask;
  m.alpha_cutoff = 0.5f;
  Scene scene = quad_scene(-10, 10, -10, 10, m);
  scene.materials[0].base_color.a = 0.25f;
  RangePass range(W, H);
  range.set_scene(scene);
  run_to_convergence(range);
  Image depth = range.depth_image();
  for (float v : depth.pixels) ASSERT_EQ(v, kBackgroundDepth);
}

TEST(RangePass, EscapingRaysTakeTheCompressedEnvironment) {
  test::osmesa_context();
  Scene scene = quad_scene(-10, 0, -10, 10);  // left half of the view; the right half sees the sky
  Environment env;  // radiance varies per texel (0.5 ... 63), so a wrong direction shows
  env.image.width = 64;
  env.image.height = 32;
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 64; ++x) env.image.texels.push_back(glm::vec4(0.5f + x, 0.1f * (y + 1), 2.0f, 1.0f));
  env.strength = 1.5f;
  scene.environment = env;
  RangePass range(W, H);
  range.set_scene(scene);
  run_to_convergence(range);
  Image color = range.range_color_image(), depth = range.depth_image();
  for (int y = 0; y < H; ++y)
    for (int x = W / 2 + 2; x < W; ++x) {
      glm::vec3 expected(0.0f);  // the average over the same jittered rays
      for (int k = 0; k < range.frames(); ++k) {
        glm::vec2 j = raster_jitter(k);
        Ray ray = camera_ray(Camera{}, W, H, x + j.x, y + j.y);
        expected += range_environment_color(glm::vec3(sample_texture(env.image, equirect_uv(ray.direction))) * 1.5f);
      }
      expected /= float(range.frames());
      for (int c = 0; c < 3; ++c) ASSERT_NEAR(color.at(x, y, c), expected[c], 2e-3f) << x << "," << y << " " << c;
      ASSERT_EQ(depth.at(x, y, 0), kBackgroundDepth);
    }
  // The quad still covers the left half.
  glm::vec3 c;
  float d;
  expected_at(3, 5, c, d, range.frames());
  EXPECT_NEAR(color.at(3, 5, 0), c.x, 1e-4f);
}

TEST(RangePass, SpecularPixelsTakeTheChainResult) {
  test::osmesa_context();
  Material mirror;
  mirror.metallic = 1.0f;
  mirror.roughness = 0.0f;
  Scene scene = quad_scene(-10, 0, -10, 10, mirror);  // left half of the view
  scene.materials[0].metallic = 1.0f;
  RangePass range(W, H);
  range.set_scene(scene);
  int calls = 0;
  auto tracer = [&](const std::vector<uint32_t>& pixels, glm::vec2 jitter) {
    ++calls;
    EXPECT_EQ(jitter, raster_jitter(range.frames()));
    std::vector<SpecularChainHit> hits(pixels.size());
    for (size_t i = 0; i < pixels.size(); ++i) {
      EXPECT_LT(pixels[i] % W, uint32_t(W / 2 + 1));
      hits[i] = {glm::vec3(0.3f, 0.6f, 0.9f), 7.0f, true};
    }
    return hits;
  };
  run_to_convergence(range, tracer);
  EXPECT_EQ(calls, range.frames());
  Image color = range.range_color_image(), depth = range.depth_image();
  EXPECT_NEAR(color.at(3, 5, 1), 0.6f, 1e-6f);
  EXPECT_NEAR(depth.at(3, 5, 0), 7.0f, 1e-5f);
  EXPECT_EQ(color.at(W - 3, 5, 1), 0.0f);
  // Without a specular surface in the scene no callback happens.
  RangePass plain(W, H);
  plain.set_scene(quad_scene(-10, 0, -10, 10));
  calls = 0;
  run_to_convergence(plain, tracer);
  EXPECT_EQ(calls, 0);
}

}  // namespace
}  // namespace pxf
