// Compute dispatches and allocations within the current GL context's limits. A context may refuse
// a dispatch of more than GL_MAX_COMPUTE_WORK_GROUP_COUNT groups along an axis (65,535 on llvmpipe
// and most GPUs, the least the spec allows) and a texture wider or taller than GL_MAX_TEXTURE_SIZE;
// it then raises a GL error after the work it was meant for (the tracing) is done. Here a 1D pass
// of any size is laid out as a 2D grid of groups instead, and what no layout can fit is refused
// with a one-line pxf::Error when it is allocated, before any tracing. Not checked:
// GL_MAX_SHADER_STORAGE_BLOCK_SIZE, which llvmpipe reports as 128 MiB but does not enforce on a
// buffer bound to a runtime-sized array (the grid filter's 136 MB grid at 16384x100, sigma_s 0.1,
// matches the CPU reference: gl/dispatch_test.cpp); refusing on it would refuse renders that work.
#pragma once
#include <cstdint>
#include <string>

namespace pxf {

// The limits of the current context that pxf's passes can reach.
struct GlLimits {
  uint32_t max_work_groups[3] = {65535, 65535, 65535};  // GL_MAX_COMPUTE_WORK_GROUP_COUNT per axis
  int max_texture_size = 16384;                         // GL_MAX_TEXTURE_SIZE
};
GlLimits query_gl_limits();  // needs a current context

// Work groups along x and y.
struct WorkGroupGrid {
  uint32_t x = 0, y = 0;
  uint64_t count() const { return uint64_t(x) * y; }
};

// The grid of work groups that covers `groups` groups of a 1D pass: one row while they fit the x
// limit, else rows of limits.max_work_groups[0] (the last groups of the last row find their linear
// index past the end and return: flat_work_group() in shaders/grid_common.glsl). Throws pxf::Error
// when even that needs more rows than the y limit allows.
WorkGroupGrid work_group_grid(uint64_t groups, const GlLimits& limits);

// Throws pxf::Error (one line, naming `what`) when a dispatch of x * y * z groups exceeds the limits.
void check_work_groups(const char* what, uint64_t x, uint64_t y, uint64_t z, const GlLimits& limits);

// Dispatches the bound compute program over `groups` work groups of a 1D pass (work_group_grid of
// the context's limits); the shader reads its linear group with flat_work_group().
void dispatch_compute_1d(const char* what, uint64_t groups);
// glDispatchCompute after check_work_groups against the context's limits.
void dispatch_compute(const char* what, uint64_t x, uint64_t y, uint64_t z = 1);

// Throws pxf::Error when a `width` x `height` texture exceeds `limits.max_texture_size`.
void check_texture_size(const std::string& what, int width, int height, const GlLimits& limits);

}  // namespace pxf
