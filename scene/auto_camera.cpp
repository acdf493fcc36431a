// Automatic framing camera (auto_camera.h).
#include "scene/auto_camera.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/gtc/matrix_transform.hpp>

namespace pxf {
namespace {

constexpr float kDegree = 3.14159265358979f / 180.0f;

// Unit direction from the model toward the camera; azimuth from +Z toward +X.
glm::vec3 view_direction(float azimuth, float elevation) {
  return {std::cos(elevation) * std::sin(azimuth), std::sin(elevation), std::cos(elevation) * std::cos(azimuth)};
}

// The three-quarter direction with the largest projected area. The grid is fine enough (2.5
// degrees) that the choice is stable; ties keep the first, nearest the classic 45/30 degree view.
glm::vec3 best_view_direction(glm::vec3 size) {
  glm::vec3 best = view_direction(45.0f * kDegree, 30.0f * kDegree);
  float best_area = projected_box_area(size, best) * (1.0f + 1e-4f);
  for (float az = 20.0f; az <= 70.0f + 1e-3f; az += 2.5f)
    for (float el = 15.0f; el <= 50.0f + 1e-3f; el += 2.5f) {
      glm::vec3 d = view_direction(az * kDegree, el * kDegree);
      float area = projected_box_area(size, d);
      if (area > best_area) best_area = area, best = d;
    }
  return best;
}

struct Frame {
  glm::vec3 right, up, forward;
};

Frame camera_frame(glm::vec3 toward_camera) {
  Frame f;
  f.forward = -toward_camera;
  f.right = glm::normalize(glm::cross(f.forward, glm::vec3(0.0f, 1.0f, 0.0f)));
  f.up = glm::cross(f.right, f.forward);
  return f;
}

// The smallest distance from `target` along -forward at which every corner lies within
// `fill` x the half-extents tan_x, tan_y of the view.
float fit_distance(const glm::vec3 corners[8], glm::vec3 target, const Frame& f, float tan_x, float tan_y) {
  float distance = 0.0f;
  for (int i = 0; i < 8; ++i) {
    glm::vec3 q = corners[i] - target;
    float depth_offset = glm::dot(q, f.forward);
    distance = std::max(distance, std::fabs(glm::dot(q, f.right)) / tan_x - depth_offset);
    distance = std::max(distance, std::fabs(glm::dot(q, f.up)) / tan_y - depth_offset);
  }
  return distance;
}

// Moves the target so that the projected box is centered (perspective makes the near corners
// project larger, so the box center is not the image center).
glm::vec3 center_projection(const glm::vec3 corners[8], glm::vec3 target, float distance, const Frame& f) {
  glm::vec2 lo(1e30f), hi(-1e30f);
  glm::vec3 eye = target - f.forward * distance;
  for (int i = 0; i < 8; ++i) {
    glm::vec3 q = corners[i] - eye;
    float depth = glm::dot(q, f.forward);
    glm::vec2 p(glm::dot(q, f.right) / depth, glm::dot(q, f.up) / depth);
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  glm::vec2 middle = 0.5f * (lo + hi);  // in tan units at the target's depth
  return target + (f.right * middle.x + f.up * middle.y) * distance;
}

}  // namespace

float projected_box_area(glm::vec3 size, glm::vec3 d) {
  return std::fabs(d.x) * size.y * size.z + std::fabs(d.y) * size.x * size.z + std::fabs(d.z) * size.x * size.y;
}

Camera frame_scene(const Scene& scene, float aspect) {
  glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
  for (const Mesh& mesh : scene.meshes)
    for (const glm::uvec3& t : mesh.triangles)
      for (uint32_t v : {t.x, t.y, t.z}) {
        lo = glm::min(lo, mesh.positions[v]);
        hi = glm::max(hi, mesh.positions[v]);
      }
  if (!(lo.x <= hi.x)) lo = glm::vec3(-0.5f), hi = glm::vec3(0.5f);
  return frame_bounds(lo, hi, aspect);
}

Camera frame_bounds(glm::vec3 lo, glm::vec3 hi, float aspect, float fill) {
  Camera camera;
  // A box too small for float arithmetic at its position (a model of 1e-38 units, or of 1e-9 units
  // at 1000) would put the eye on the target, or square distances to 0: the camera would be NaN.
  // Such a box is framed as a cube of the smallest workable size around its center instead.
  {
    const glm::vec3 center = 0.5f * lo + 0.5f * hi;
    const float magnitude = std::max({std::fabs(center.x), std::fabs(center.y), std::fabs(center.z)});
    const float smallest = std::max(1e-15f, 1e-5f * magnitude);
    if (!(std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z}) >= smallest)) {
      lo = center - glm::vec3(0.5f * smallest);
      hi = center + glm::vec3(0.5f * smallest);
    }
  }
  // A tiny floor on each extent keeps a flat or a line-like model's box from degenerating.
  float extent = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z, 1e-3f});
  glm::vec3 size = glm::max(hi - lo, glm::vec3(1e-4f * extent));
  Frame f = camera_frame(best_view_direction(size));
  glm::vec3 corners[8];
  for (int i = 0; i < 8; ++i) corners[i] = {i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z};
  float tan_y = std::tan(0.5f * camera.yfov) * fill;
  float tan_x = tan_y * std::max(aspect, 1e-3f);
  glm::vec3 target = 0.5f * (lo + hi);
  float distance = fit_distance(corners, target, f, tan_x, tan_y);
  for (int i = 0; i < 4; ++i) {  // a few rounds: each recentering shrinks the offset tenfold or more
    target = center_projection(corners, target, distance, f);
    distance = fit_distance(corners, target, f, tan_x, tan_y);
  }
  glm::vec3 eye = target - f.forward * distance;
  camera.camera_to_world = glm::inverse(glm::lookAt(eye, target, f.up));
  float radius = 0.5f * glm::length(hi - lo);
  camera.znear = std::max(std::min(distance - radius, distance) * 0.5f, std::max(distance * 1e-3f, 1e-4f));
  camera.zfar = (distance + radius) * 2.0f;
  return camera;
}

}  // namespace pxf
