// Camera rays and the matching GL matrices (camera.h). Both derive from the same pinhole model so
// that the raster range pass sees exactly what camera_ray traces.
#include "scene/camera.h"

#include <cmath>

namespace pxf {
namespace {

// The image size wins over the glTF aspectRatio (a resized window must not stretch the view).
float image_aspect(int width, int height) {
  return height > 0 ? static_cast<float>(width) / static_cast<float>(height) : 1.0f;
}

}  // namespace

CameraRays::CameraRays(const Camera& camera, int width, int height)
    : basis_(glm::mat3(camera.camera_to_world)),
      origin_(glm::vec3(camera.camera_to_world[3])),
      orthographic_(camera.orthographic),
      half_height_(camera.orthographic ? camera.ymag : std::tan(0.5f * camera.yfov)),
      aspect_(image_aspect(width, height)),
      width_(static_cast<float>(width)),
      height_(static_cast<float>(height)) {}

Ray CameraRays::operator()(float px, float py) const {
  float ndc_x = 2.0f * px / width_ - 1.0f;
  float ndc_y = 1.0f - 2.0f * py / height_;  // row 0 is the top row
  glm::vec3 on_plane(ndc_x * half_height_ * aspect_, ndc_y * half_height_, 0.0f);
  Ray ray;
  if (orthographic_) {
    ray.origin = origin_ + basis_ * on_plane;
    ray.direction = glm::normalize(basis_ * glm::vec3(0.0f, 0.0f, -1.0f));
  } else {
    ray.origin = origin_;
    ray.direction = glm::normalize(basis_ * (on_plane + glm::vec3(0.0f, 0.0f, -1.0f)));
  }
  return ray;
}

Ray camera_ray(const Camera& camera, int width, int height, float px, float py) {
  return CameraRays(camera, width, height)(px, py);
}

glm::mat4 camera_view_matrix(const Camera& camera) { return glm::inverse(camera.camera_to_world); }

glm::mat4 camera_projection_matrix(const Camera& camera, int width, int height, glm::vec2 jitter) {
  // Standard GL perspective or orthographic (right-handed, clip z in [-1, 1]).
  float aspect = image_aspect(width, height);
  float n = camera.znear, fa = camera.zfar;
  glm::mat4 p(0.0f);
  if (camera.orthographic) {
    p[0][0] = 1.0f / (camera.ymag * aspect);
    p[1][1] = 1.0f / camera.ymag;
    p[2][2] = 2.0f / (n - fa);
    p[3][2] = (fa + n) / (n - fa);
    p[3][3] = 1.0f;
  } else {
    float f = 1.0f / std::tan(0.5f * camera.yfov);
    p[0][0] = f / aspect;
    p[1][1] = f;
    p[2][2] = (fa + n) / (n - fa);
    p[2][3] = -1.0f;
    p[3][2] = 2.0f * fa * n / (n - fa);
  }
  // GL samples window pixel (x, y) at (x + 0.5, y + 0.5); that sample must be the ray through
  // image position (x + jitter.x, y + jitter.y), with window row y = image row y (flipped). So
  // window = image + (0.5 - jitter): flip y in NDC, then shift NDC by 2 (0.5 - jitter) / size.
  // The flip reverses the winding of projected triangles (front faces become clockwise).
  float dx = 2.0f * (0.5f - jitter.x) / static_cast<float>(width);
  float dy = 2.0f * (0.5f - jitter.y) / static_cast<float>(height);
  glm::mat4 shift_flip(1.0f);
  shift_flip[1][1] = -1.0f;
  shift_flip[3][0] = dx;  // x' = x + dx w
  shift_flip[3][1] = dy;  // y' = -y + dy w
  return shift_flip * p;
}

glm::vec2 raster_jitter(int frame) {
  // R2 low-discrepancy sequence (Roberts 2018), starting at the pixel center.
  const double g = 1.32471795724474602596;
  const double a1 = 1.0 / g, a2 = 1.0 / (g * g);
  double x = 0.5 + a1 * frame, y = 0.5 + a2 * frame;
  return glm::vec2(static_cast<float>(x - std::floor(x)), static_cast<float>(y - std::floor(y)));
}

}  // namespace pxf
