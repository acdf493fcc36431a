#version 450 core
// Bilateral grid, step 3: blur along one axis (x or y, one dispatch each; z is blurred in the splat) with the
// binomial taps g = 1/4 [1 2 1] (pass_formulas.h); taps outside the grid are left out. The value sums (a, and the
// linear sums b.zw) take g, the squared-weight sums (b.xy) take g^2: the variance of a linear
// combination of independent cells. Mirrors blur() in gl/grid_reference.cpp.
#include "pass_formulas.h"
#include "grid_common.glsl"
layout(local_size_x = 64) in;
#include "flat_dispatch.glsl"

layout(std430, binding = kBufferGrid) readonly buffer Source { vec4 src[]; };
layout(std430, binding = kBufferGridTarget) writeonly buffer Target { vec4 dst[]; };
uniform ivec2 grid_xy;  // nx, ny (nz = kGridRangeCells)
uniform int grid_z_cells;
uniform int axis;       // 0: x, 1: y, 2: z

void main() {
  int cell = flat_invocation();
  int plane = grid_xy.x * grid_xy.y;
  if (cell >= plane * grid_z_cells) return;
  ivec3 c = ivec3(cell % grid_xy.x, (cell / grid_xy.x) % grid_xy.y, cell / plane);
  int n = axis == 0 ? grid_xy.x : axis == 1 ? grid_xy.y : grid_z_cells;
  int stride = axis == 0 ? 1 : axis == 1 ? grid_xy.x : plane;
  int at = c[axis];
  vec4 a = vec4(0.0), b = vec4(0.0);
  for (int t = 0; t <= 2 * kGridBlurRadius; ++t) {
    int q = at + t - kGridBlurRadius;
    if (q < 0 || q >= n) continue;
    int other = cell + (q - at) * stride;
    float g = kGridBlurTaps[t];
    a += g * src[2 * other];
    b += vec4(g * g, g * g, g, g) * src[2 * other + 1];
  }
  dst[2 * cell] = a;
  dst[2 * cell + 1] = b;
}
