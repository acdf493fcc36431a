#include "gl/dispatch.h"

#include <algorithm>

#include "core/error.h"
#include "gl/gl.h"

namespace pxf {

GlLimits query_gl_limits() {
  GlLimits limits;
  for (GLuint axis = 0; axis < 3; ++axis) {
    GLint count = 0;
    glGetIntegeri_v(GL_MAX_COMPUTE_WORK_GROUP_COUNT, axis, &count);
    if (count > 0) limits.max_work_groups[axis] = static_cast<uint32_t>(count);
  }
  GLint texture_size = 0;
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &texture_size);
  if (texture_size > 0) limits.max_texture_size = texture_size;
  return limits;
}

WorkGroupGrid work_group_grid(uint64_t groups, const GlLimits& limits) {
  const uint64_t max_x = limits.max_work_groups[0];
  WorkGroupGrid grid;
  grid.x = static_cast<uint32_t>(std::min<uint64_t>(groups, max_x));
  const uint64_t rows = grid.x == 0 ? 0 : (groups + max_x - 1) / max_x;
  if (rows > limits.max_work_groups[1])
    throw Error(std::to_string(groups) + " work groups exceed this GL context's " + std::to_string(max_x) + " x " +
                std::to_string(limits.max_work_groups[1]));
  grid.y = static_cast<uint32_t>(rows);
  return grid;
}

void check_work_groups(const char* what, uint64_t x, uint64_t y, uint64_t z, const GlLimits& limits) {
  const uint64_t size[3] = {x, y, z};
  for (int axis = 0; axis < 3; ++axis)
    if (size[axis] > limits.max_work_groups[axis])
      throw Error(std::string(what) + ": " + std::to_string(size[axis]) + " work groups along axis " +
                  std::to_string(axis) + ", more than this GL context's " + std::to_string(limits.max_work_groups[axis]));
}

void dispatch_compute_1d(const char* what, uint64_t groups) {
  WorkGroupGrid grid;
  try {
    grid = work_group_grid(groups, query_gl_limits());
  } catch (const Error& e) {
    throw Error(std::string(what) + ": " + e.what());
  }
  if (grid.count() > 0) glDispatchCompute(grid.x, grid.y, 1);
}

void dispatch_compute(const char* what, uint64_t x, uint64_t y, uint64_t z) {
  check_work_groups(what, x, y, z, query_gl_limits());
  if (x > 0 && y > 0 && z > 0)
    glDispatchCompute(static_cast<GLuint>(x), static_cast<GLuint>(y), static_cast<GLuint>(z));
}

void check_texture_size(const std::string& what, int width, int height, const GlLimits& limits) {
  if (width > limits.max_texture_size || height > limits.max_texture_size)
    throw Error(what + ": " + std::to_string(width) + "x" + std::to_string(height) +
                " is larger than this GL context's largest texture, " + std::to_string(limits.max_texture_size) +
                " texels a side");
}

}  // namespace pxf
