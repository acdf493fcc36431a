// The automatic camera frames a model's bounding box from a three-quarter view.
#include "scene/auto_camera.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "scene/camera.h"

namespace pxf {
namespace {

struct ScreenBox {
  glm::vec2 lo{1e30f}, hi{-1e30f};  // NDC, [-1, 1] = the frame
  bool in_front = true;
};

// The box's corners projected with the raster pass's matrices (camera_test.cpp checks that they
// agree with the traced rays).
ScreenBox project_box(const Camera& camera, glm::vec3 lo, glm::vec3 hi, int width, int height) {
  glm::mat4 vp = camera_projection_matrix(camera, width, height, glm::vec2(0.5f)) * camera_view_matrix(camera);
  ScreenBox box;
  for (int i = 0; i < 8; ++i) {
    glm::vec3 c(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z);
    glm::vec4 clip = vp * glm::vec4(c, 1.0f);
    box.in_front &= clip.w > 0.0f && clip.z > -clip.w && clip.z < clip.w;  // between znear and zfar
    glm::vec2 ndc = glm::vec2(clip) / clip.w;
    box.lo = glm::min(box.lo, ndc);
    box.hi = glm::max(box.hi, ndc);
  }
  return box;
}

// Inside the frame and filling at least `fill` of it along one axis, centered.
void expect_framed(const Camera& camera, glm::vec3 lo, glm::vec3 hi, int width, int height, const char* what) {
  ScreenBox box = project_box(camera, lo, hi, width, height);
  EXPECT_TRUE(box.in_front) << what;
  EXPECT_GE(box.lo.x, -1.0f) << what;
  EXPECT_GE(box.lo.y, -1.0f) << what;
  EXPECT_LE(box.hi.x, 1.0f) << what;
  EXPECT_LE(box.hi.y, 1.0f) << what;
  glm::vec2 extent = 0.5f * (box.hi - box.lo);
  EXPECT_GT(std::max(extent.x, extent.y), 0.85f) << what << ": " << extent.x << " x " << extent.y;
  glm::vec2 middle = 0.5f * (box.hi + box.lo);
  EXPECT_NEAR(middle.x, 0.0f, 0.02f) << what;
  EXPECT_NEAR(middle.y, 0.0f, 0.02f) << what;
}

glm::vec3 eye_of(const Camera& c) { return glm::vec3(c.camera_to_world[3]); }
glm::vec3 forward_of(const Camera& c) { return -glm::vec3(c.camera_to_world[2]); }

TEST(AutoCamera, CubeIsSeenAlongItsDiagonalAndFillsTheFrame) {
  glm::vec3 lo(1.0f, 2.0f, 3.0f), hi(3.0f, 4.0f, 5.0f);
  Camera camera = frame_bounds(lo, hi);
  expect_framed(camera, lo, hi, 64, 64, "cube");
  // The largest projected area of a cube is along its diagonal: front, right, above.
  glm::vec3 d = -forward_of(camera);
  EXPECT_NEAR(d.x, 1.0f / std::sqrt(3.0f), 0.03f);
  EXPECT_NEAR(d.y, 1.0f / std::sqrt(3.0f), 0.03f);
  EXPECT_NEAR(d.z, 1.0f / std::sqrt(3.0f), 0.03f);
  expect_framed(frame_bounds(lo, hi, 4.0f / 3.0f), lo, hi, 320, 240, "cube 4:3");
  expect_framed(frame_bounds(lo, hi, 0.5f), lo, hi, 32, 64, "cube 1:2");
}

TEST(AutoCamera, FlatXzModelIsSeenFromAboveAtAnAngle) {
  glm::vec3 lo(-1.0f, 0.0f, -1.0f), hi(1.0f, 0.0f, 1.0f);
  Camera camera = frame_bounds(lo, hi);
  expect_framed(camera, lo, hi, 64, 64, "flat quad");
  glm::vec3 d = -forward_of(camera);
  float elevation = std::asin(d.y);
  EXPECT_GT(elevation, 45.0f * 3.14159265f / 180.0f);  // well above the plane, not edge-on
  EXPECT_LT(elevation, 60.0f * 3.14159265f / 180.0f);  // still an angled view
  EXPECT_GT(eye_of(camera).y, 0.5f);
}

TEST(AutoCamera, LongRodIsSeenFromItsSide) {
  glm::vec3 lo(-2.0f, -0.05f, -0.05f), hi(2.0f, 0.05f, 0.05f);
  Camera camera = frame_bounds(lo, hi, 4.0f / 3.0f);
  expect_framed(camera, lo, hi, 320, 240, "rod");
  // Mostly across the rod (its long axis is X): the view direction's X part is the smallest.
  glm::vec3 d = -forward_of(camera);
  EXPECT_LT(std::fabs(d.x), 0.5f);
  ScreenBox box = project_box(camera, lo, hi, 320, 240);
  EXPECT_GT(box.hi.x - box.lo.x, 1.7f);  // it spans the width
}

TEST(AutoCamera, ProjectedAreaOfABox) {
  glm::vec3 size(1.0f, 2.0f, 3.0f);
  EXPECT_FLOAT_EQ(projected_box_area(size, {0, 0, 1}), 2.0f);
  EXPECT_FLOAT_EQ(projected_box_area(size, {0, -1, 0}), 3.0f);
  EXPECT_NEAR(projected_box_area(size, glm::normalize(glm::vec3(1, 1, 1))), (6.0f + 3.0f + 2.0f) / std::sqrt(3.0f), 1e-5f);
}

}  // namespace
}  // namespace pxf

namespace pxf {

// Boxes too small for float arithmetic where they are (found by the glTF fuzzer: a model of 1e-38
// units gave a NaN camera, and Embree aborted on its rays) are framed as the smallest workable cube
// around their center: finite rays that look at the model.
TEST(AutoCamera, BoxesBelowFloatResolutionGiveAFiniteCameraLookingAtThem) {
  const glm::vec3 cases[][2] = {{glm::vec3(0.0f), glm::vec3(1e-38f)},
                                {glm::vec3(0.0f, 1.7e-38f, 5.8e-39f), glm::vec3(0.0f, 1.7e-38f, 5.8e-39f)},
                                {glm::vec3(1000.0f), glm::vec3(1000.0f) + glm::vec3(1e-9f)},
                                {glm::vec3(1e6f, -1e6f, 3e5f), glm::vec3(1e6f, -1e6f, 3e5f)}};
  for (const auto& box : cases) {
    const Camera camera = frame_bounds(box[0], box[1], 1.5f);
    const glm::vec3 center = 0.5f * box[0] + 0.5f * box[1];
    for (float px : {0.0f, 32.0f, 64.0f}) {
      const Ray ray = camera_ray(camera, 64, 64, px, px);
      ASSERT_TRUE(std::isfinite(ray.origin.x) && std::isfinite(ray.origin.y) && std::isfinite(ray.origin.z));
      ASSERT_TRUE(std::isfinite(ray.direction.x) && std::isfinite(ray.direction.y) && std::isfinite(ray.direction.z));
      EXPECT_NEAR(glm::length(ray.direction), 1.0f, 1e-5f);
    }
    const Ray middle = camera_ray(camera, 64, 64, 32.0f, 32.0f);
    const glm::vec3 to_center = center - middle.origin;
    ASSERT_GT(glm::length(to_center), 0.0f);
    EXPECT_GT(glm::dot(glm::normalize(to_center), middle.direction), 0.99f) << center.x;
  }
}

}  // namespace pxf
