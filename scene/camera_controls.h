// Camera controls: orbit around a target, pan, zoom (dolly) and fly, for the explorer, camera paths
// and the motion bench. Pure math on pxf::Camera, no GL and no GUI, so it is unit-tested.
// Usage:
//   CameraController control(scene.camera, scene_bounds(scene));
//   control.orbit(dx, dy); control.pan(dx, dy, image_height); control.zoom(wheel);
//   control.fly({0, 0, 1}, seconds);   // forward
//   preview.set_camera(control.camera());
#pragma once
#include <glm/glm.hpp>
#include "scene/scene.h"

namespace pxf {

struct Bounds {
  glm::vec3 lo{0.0f}, hi{0.0f};
  glm::vec3 center() const { return 0.5f * (lo + hi); }
  float radius() const;  // half the diagonal; at least a small positive length
};
Bounds scene_bounds(const Scene& scene);

class CameraController {
 public:
  // `home`: the scene's camera; the orbit target is on its view axis, as deep as the scene center.
  CameraController(const Camera& home, const Bounds& bounds);

  // Mouse drags in pixels: orbit turns around the target (0.005 rad per pixel), pan moves the
  // camera so that the target plane follows the cursor in an image `image_height` pixels tall.
  void orbit(float dx, float dy);
  void pan(float dx, float dy, float image_height);
  void zoom(float wheel_steps);  // > 0: closer
  // Moves camera and target; `direction` in camera space: x right, y up, z forward.
  void fly(const glm::vec3& direction, float seconds);
  void reset();  // back to the home camera exactly

  const Camera& camera() const { return camera_; }
  glm::vec3 eye() const { return eye_; }
  glm::vec3 target() const { return target_; }

 private:
  void update_camera();

  Camera home_, camera_;
  Bounds bounds_;
  glm::vec3 eye_{0.0f}, target_{0.0f};
};

}  // namespace pxf
