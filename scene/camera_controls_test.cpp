// The camera controls (scene/camera_controls.h): pure math on pxf::Camera.
#include <gtest/gtest.h>

#include <cmath>

#include "scene/camera_controls.h"

namespace pxf {
namespace {

Camera test_camera() {
  Camera c;
  c.camera_to_world[3] = glm::vec4(0.0f, 1.0f, 5.0f, 1.0f);  // looking down -Z at the origin
  return c;
}
const Bounds kUnitBox{glm::vec3(-1.0f), glm::vec3(1.0f)};

void expect_near(const glm::vec3& a, const glm::vec3& b, float tol = 1e-4f) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

TEST(CameraControls, StartsAndResetsAtTheSceneCameraExactly) {
  CameraController control(test_camera(), kUnitBox);
  EXPECT_EQ(control.camera().camera_to_world, test_camera().camera_to_world);
  expect_near(control.target(), glm::vec3(0.0f, 1.0f, 0.0f));  // on the view axis, as deep as the center
  control.orbit(40, 10);
  control.pan(5, 5, 100);
  control.zoom(2);
  EXPECT_NE(control.camera().camera_to_world, test_camera().camera_to_world);
  control.reset();
  EXPECT_EQ(control.camera().camera_to_world, test_camera().camera_to_world);
}

TEST(CameraControls, OrbitKeepsTheDistanceAndLooksAtTheTarget) {
  CameraController control(test_camera(), kUnitBox);
  const float distance = glm::length(control.eye() - control.target());
  control.orbit(120, -60);
  EXPECT_NEAR(glm::length(control.eye() - control.target()), distance, 1e-4f);
  const glm::vec3 forward = -glm::vec3(control.camera().camera_to_world[2]);
  expect_near(glm::normalize(forward), glm::normalize(control.target() - control.eye()));
  expect_near(glm::vec3(control.camera().camera_to_world[3]), control.eye());
  control.orbit(0, 10000);  // pitch is clamped short of the pole: the frame stays orthonormal
  EXPECT_NEAR(glm::length(glm::vec3(control.camera().camera_to_world[0])), 1.0f, 1e-4f);
}

TEST(CameraControls, PanMovesEyeAndTargetTogetherZoomAndFlyMoveAlongTheView) {
  CameraController control(test_camera(), kUnitBox);
  control.pan(-10, 0, 100);  // drag left: the camera moves right (+X)
  expect_near(control.eye() - control.target(), glm::vec3(0.0f, 0.0f, 5.0f));
  EXPECT_GT(control.eye().x, 0.0f);
  control.zoom(1);
  EXPECT_LT(glm::length(control.eye() - control.target()), 5.0f);
  const glm::vec3 before = control.eye();
  control.fly(glm::vec3(0, 0, 1), 1.0f);  // forward = -Z here
  EXPECT_LT(control.eye().z, before.z);
  EXPECT_NEAR(control.eye().x, before.x, 1e-4f);
}

// An orthographic camera: zoom narrows the view (moving would change nothing on screen), pan
// moves by the view height (2 ymag) per image height, reset restores ymag.
TEST(CameraControls, OrthographicZoomNarrowsTheViewAndPanFollowsTheCursor) {
  Camera home = test_camera();
  home.orthographic = true;
  home.ymag = 2.0f;
  CameraController control(home, kUnitBox);
  const glm::vec3 eye = control.eye();
  control.zoom(1);
  EXPECT_NEAR(control.camera().ymag, 2.0f * 0.85f, 1e-6f);
  expect_near(control.eye(), eye);
  control.pan(-50, 0, 100);  // half the image height to the left: the camera moves ymag to the right
  EXPECT_NEAR(control.eye().x - eye.x, 0.5f * 2.0f * control.camera().ymag, 1e-4f);
  EXPECT_TRUE(control.camera().orthographic);
  control.reset();
  EXPECT_FLOAT_EQ(control.camera().ymag, 2.0f);
}

}  // namespace
}  // namespace pxf
