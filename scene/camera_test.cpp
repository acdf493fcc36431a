// The raster pass's matrices must project camera_ray's points back onto the pixel they came from.
#include <gtest/gtest.h>

#include "scene/camera.h"
#include "testing/shapes.h"

namespace pxf {
namespace {

// Window coordinates (GL: pixel (x, y) is sampled at (x + 0.5, y + 0.5)) of a world point.
glm::vec3 window_of(const glm::mat4& view_projection, glm::vec3 p, int width, int height) {
  glm::vec4 clip = view_projection * glm::vec4(p, 1.0f);
  glm::vec3 ndc = glm::vec3(clip) / clip.w;
  return glm::vec3((ndc.x + 1.0f) * 0.5f * width, (ndc.y + 1.0f) * 0.5f * height, ndc.z);
}

void expect_projection_matches_camera_rays(const Camera& camera) {
  const int width = 64, height = 40;
  for (glm::vec2 jitter : {glm::vec2(0.5f), glm::vec2(0.0f), glm::vec2(0.9f, 0.1f), raster_jitter(7)}) {
    glm::mat4 vp = camera_projection_matrix(camera, width, height, jitter) * camera_view_matrix(camera);
    for (int y : {0, 1, 17, height - 1}) {
      for (int x : {0, 5, 33, width - 1}) {
        Ray ray = camera_ray(camera, width, height, x + jitter.x, y + jitter.y);
        for (float t : {0.5f, 3.7f, 40.0f}) {
          glm::vec3 w = window_of(vp, ray.origin + t * ray.direction, width, height);
          // Window row y is image row y (row 0 = top): the sample lands on that pixel's center.
          EXPECT_NEAR(w.x, x + 0.5f, 2e-3f) << "x " << x << " y " << y << " t " << t;
          EXPECT_NEAR(w.y, y + 0.5f, 2e-3f) << "x " << x << " y " << y << " t " << t;
          EXPECT_GT(w.z, -1.0f);
          EXPECT_LT(w.z, 1.0f);
        }
      }
    }
  }
}

TEST(Camera, ProjectionMatchesCameraRayForAnyJitter) {
  Camera camera = look_at_camera(glm::vec3(1.0f, 2.0f, 5.0f), glm::vec3(0.2f, 0.5f, 0.0f), glm::vec3(0, 1, 0), 0.8f);
  camera.znear = 0.05f;
  camera.zfar = 100.0f;
  expect_projection_matches_camera_rays(camera);
}

TEST(Camera, OrthographicProjectionMatchesCameraRayForAnyJitter) {
  Camera camera = look_at_camera(glm::vec3(1.0f, 2.0f, 5.0f), glm::vec3(0.2f, 0.5f, 0.0f), glm::vec3(0, 1, 0), 0.8f);
  camera.orthographic = true;
  camera.ymag = 1.7f;
  camera.znear = 0.0f;
  camera.zfar = 100.0f;
  expect_projection_matches_camera_rays(camera);
}

TEST(Camera, OrthographicRaysAreParallelAndSpanTwiceYmag) {
  Camera camera;  // identity: looks down -z, +y up
  camera.orthographic = true;
  camera.ymag = 2.0f;
  Ray top = camera_ray(camera, 100, 50, 50.0f, 0.0f);
  Ray corner = camera_ray(camera, 100, 50, 100.0f, 50.0f);
  EXPECT_EQ(top.direction, glm::vec3(0, 0, -1));
  EXPECT_EQ(corner.direction, glm::vec3(0, 0, -1));
  EXPECT_NEAR(top.origin.y, 2.0f, 1e-6f);
  EXPECT_NEAR(top.origin.x, 0.0f, 1e-6f);
  // The image aspect (2:1) sets the width: xmag = 2 ymag.
  EXPECT_NEAR(corner.origin.x, 4.0f, 1e-6f);
  EXPECT_NEAR(corner.origin.y, -2.0f, 1e-6f);
}

TEST(Camera, TopRowLooksUpAndRaysAreUnit) {
  Camera camera;  // identity: looks down -z, +y up
  Ray top = camera_ray(camera, 100, 50, 50.0f, 0.0f);
  Ray bottom = camera_ray(camera, 100, 50, 50.0f, 50.0f);
  Ray center = camera_ray(camera, 100, 50, 50.0f, 25.0f);
  EXPECT_GT(top.direction.y, 0.0f);
  EXPECT_LT(bottom.direction.y, 0.0f);
  EXPECT_NEAR(center.direction.z, -1.0f, 1e-6f);
  EXPECT_NEAR(glm::length(top.direction), 1.0f, 1e-6f);
  // Vertical field of view: the top edge is yfov/2 above the axis.
  EXPECT_NEAR(std::atan2(top.direction.y, -top.direction.z), camera.yfov / 2, 1e-5f);
}

TEST(Camera, RasterJitterStaysInThePixel) {
  EXPECT_FLOAT_EQ(raster_jitter(0).x, 0.5f);
  for (int i = 0; i < 1000; ++i) {
    glm::vec2 j = raster_jitter(i);
    ASSERT_GE(j.x, 0.0f);
    ASSERT_LT(j.x, 1.0f);
    ASSERT_GE(j.y, 0.0f);
    ASSERT_LT(j.y, 1.0f);
  }
}

}  // namespace
}  // namespace pxf
