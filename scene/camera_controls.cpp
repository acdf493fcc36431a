#include "scene/camera_controls.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <glm/gtc/matrix_transform.hpp>

namespace pxf {

namespace {
constexpr float kOrbitRadiansPerPixel = 0.005f;
constexpr float kMaxPitch = 1.55f;  // just under 90 degrees: the up vector stays defined
const glm::vec3 kWorldUp(0.0f, 1.0f, 0.0f);

glm::vec3 forward_of(const Camera& c) { return -glm::normalize(glm::vec3(c.camera_to_world[2])); }
}  // namespace

float Bounds::radius() const { return std::max(0.5f * glm::length(hi - lo), 1e-3f); }

Bounds scene_bounds(const Scene& scene) {
  Bounds b;
  b.lo = glm::vec3(std::numeric_limits<float>::max());
  b.hi = glm::vec3(-std::numeric_limits<float>::max());
  bool any = false;
  for (const Mesh& mesh : scene.meshes)
    for (const glm::vec3& p : mesh.positions) {
      b.lo = glm::min(b.lo, p);
      b.hi = glm::max(b.hi, p);
      any = true;
    }
  if (!any) b = Bounds{glm::vec3(-1.0f), glm::vec3(1.0f)};
  return b;
}

CameraController::CameraController(const Camera& home, const Bounds& bounds) : home_(home), bounds_(bounds) {
  reset();
}

void CameraController::reset() {
  camera_ = home_;
  eye_ = glm::vec3(home_.camera_to_world[3]);
  const glm::vec3 forward = forward_of(home_);
  const float depth = glm::dot(bounds_.center() - eye_, forward);
  target_ = eye_ + forward * std::max(depth, 0.1f * bounds_.radius());
}

void CameraController::update_camera() {
  const glm::vec3 forward = glm::normalize(target_ - eye_);
  // Looking straight up or down: any horizontal up keeps lookAt defined.
  const glm::vec3 up = std::abs(glm::dot(forward, kWorldUp)) > 0.999f ? glm::vec3(0, 0, -1) : kWorldUp;
  camera_.camera_to_world = glm::inverse(glm::lookAt(eye_, target_, up));
}

void CameraController::orbit(float dx, float dy) {
  const glm::vec3 offset = eye_ - target_;
  const float distance = glm::length(offset);
  float yaw = std::atan2(offset.x, offset.z);
  float pitch = std::asin(std::clamp(offset.y / distance, -1.0f, 1.0f));
  yaw -= dx * kOrbitRadiansPerPixel;
  pitch = std::clamp(pitch + dy * kOrbitRadiansPerPixel, -kMaxPitch, kMaxPitch);
  eye_ = target_ + distance * glm::vec3(std::cos(pitch) * std::sin(yaw), std::sin(pitch), std::cos(pitch) * std::cos(yaw));
  update_camera();
}

void CameraController::pan(float dx, float dy, float image_height) {
  // The view height in scene units at the target: fixed for an orthographic camera.
  const float distance = glm::length(target_ - eye_);
  const float view_height = camera_.orthographic ? 2.0f * camera_.ymag : 2.0f * distance * std::tan(0.5f * camera_.yfov);
  const float units_per_pixel = view_height / std::max(image_height, 1.0f);
  const glm::vec3 right(camera_.camera_to_world[0]), up(camera_.camera_to_world[1]);
  const glm::vec3 move = (-dx * glm::normalize(right) + dy * glm::normalize(up)) * units_per_pixel;
  eye_ += move;
  target_ += move;
  update_camera();
}

void CameraController::zoom(float wheel_steps) {
  if (camera_.orthographic) {  // moving an orthographic camera changes nothing on screen: narrow the view
    camera_.ymag = std::max(camera_.ymag * std::pow(0.85f, wheel_steps), 1e-4f * bounds_.radius());
    return;
  }
  const glm::vec3 offset = eye_ - target_;
  const float distance = std::max(glm::length(offset) * std::pow(0.85f, wheel_steps), 1e-3f * bounds_.radius());
  eye_ = target_ + glm::normalize(offset) * distance;
  update_camera();
}

void CameraController::fly(const glm::vec3& direction, float seconds) {
  const float speed = 0.5f * bounds_.radius();  // scene radii per second
  const glm::mat3 axes(camera_.camera_to_world);
  const glm::vec3 move = axes * glm::vec3(direction.x, direction.y, -direction.z) * speed * seconds;
  eye_ += move;
  target_ += move;
  update_camera();
}

}  // namespace pxf
