// Camera math shared by the path tracer and the raster range pass, so both see exactly the same
// rays. Pure math (GLM), no GL.
#pragma once
#include <glm/glm.hpp>
#include "scene/scene.h"

namespace pxf {

struct Ray {
  glm::vec3 origin;
  glm::vec3 direction;  // unit length
};

// The ray through image position (px, py) in pixels (an orthographic camera's rays are parallel
// and start on the camera's plane), (0,0) = top-left corner of the image,
// (width, height) = bottom-right. A pixel (x, y) with jitter j in [0,1)^2 uses (x + j.x, y + j.y).
Ray camera_ray(const Camera& camera, int width, int height, float px, float py);

// camera_ray for many rays of one image: the terms shared by all of them (tan, aspect, basis)
// computed once. Gives exactly camera_ray's rays.
class CameraRays {
 public:
  CameraRays(const Camera& camera, int width, int height);
  Ray operator()(float px, float py) const;

 private:
  glm::mat3 basis_;
  glm::vec3 origin_;
  bool orthographic_;
  float half_height_;  // tan(yfov / 2), or ymag for an orthographic camera
  float aspect_, width_, height_;
};

// View and projection matrices for OpenGL that rasterize exactly what camera_ray traces, with the
// whole image shifted by `jitter` pixels (jitter (0.5,0.5) = pixel centers; GL's window y is
// flipped relative to image rows, the matrix accounts for it so that row 0 is the top row).
glm::mat4 camera_view_matrix(const Camera& camera);
glm::mat4 camera_projection_matrix(const Camera& camera, int width, int height, glm::vec2 jitter);

// Per-pixel jitter of the range buffer's and the path tracer's frame `frame` (R2 sequence for the
// raster, so it converges evenly); pixel x,y of the path tracer uses its own random jitter.
glm::vec2 raster_jitter(int frame);

}  // namespace pxf
