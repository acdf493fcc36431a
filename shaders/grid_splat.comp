#version 450 core
// Bilateral grid, step 2: splat. One invocation per spatial cell (i, j) gathers the pixels whose
// nearest cell it is (scan order, so the sums match the CPU reference) into its column of
// kGridRangeCells range cells, each pixel into its nearest range cell with weight 1 (homogeneous
// coordinates), and at once blurred along z: the pixel goes into range cells k - 1 .. k + 1 with the
// blur taps g (g^2 for the squared-weight sums), which is the z pass of the separable blur done
// per pixel instead of per cell (far fewer operations: most cells are empty). Per cell, two vec4:
//   a = (sum L_u, count)
//   b = (sum Var over known variances, count of unknown ones, count of known ones, sum Var known)
// i.e. the sums sum w^2 Var, sum w^2 (unknown), sum w (known), sum w Var (known) of the exact
// filter with w = 1, which the blur and the slice then weight like the exact kernel sums.
// No atomics: every cell is written by exactly one invocation (empty cells with zeros).
// Mirrors splat() in gl/grid_reference.cpp.
#include "pass_formulas.h"
#include "grid_common.glsl"
layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = kUnitHv) uniform sampler2D hv_tex;     // rgb L_u, a Var[L_u]
layout(binding = kUnitGuide) uniform sampler2D guide_tex;  // rgb range color, a distance
layout(std430, binding = kBufferGrid) writeonly buffer Grid { vec4 cells[]; };
uniform ivec2 grid_xy;      // nx, ny
uniform float cell_s;       // pixels per spatial cell
uniform float inv_cell_s;   // 1 / cell_s (computed once on the CPU: same rounding as the reference)
uniform float min_cell_z;   // grid_min_cell_z(sigma_c)

void main() {
  ivec2 c = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(c, grid_xy))) return;
  ivec2 size = textureSize(hv_tex, 0);
  vec4 acc_a[kGridRangeCells];
  vec4 acc_b[kGridRangeCells];
  for (int k = 0; k < kGridRangeCells; ++k) acc_a[k] = acc_b[k] = vec4(0.0);
  ivec2 lo = max(ivec2(ceil((vec2(c) - 0.5) * cell_s)) - 1, ivec2(0));
  ivec2 hi = min(ivec2(floor((vec2(c) + 0.5) * cell_s)) + 1, size - 1);
  for (int y = lo.y; y <= hi.y; ++y) {
    precise float v = float(y) * inv_cell_s;
    if (nearest_cell(v) != c.y) continue;
    for (int x = lo.x; x <= hi.x; ++x) {
      precise float u = float(x) * inv_cell_s;
      if (nearest_cell(u) != c.x) continue;
      ivec2 p = ivec2(x, y);
      int k = clamp(nearest_cell(grid_z(guide_luminance(texelFetch(guide_tex, p, 0)), min_cell_z)), 0, kGridRangeCells - 1);
      vec4 hv = texelFetch(hv_tex, p, 0);
      float var = clean_var(hv.a);
      vec4 a = vec4(clean(hv.rgb), 1.0);
      vec4 b = var > 0.0 ? vec4(var, 0.0, 1.0, var) : vec4(0.0, 1.0, 0.0, 0.0);
      for (int t = 0; t <= 2 * kGridBlurRadius; ++t) {
        int q = k + t - kGridBlurRadius;
        if (q < 0 || q >= kGridRangeCells) continue;
        float g = kGridBlurTaps[t];
        acc_a[q] += g * a;
        acc_b[q] += vec4(g * g, g * g, g, g) * b;
      }
    }
  }
  for (int k = 0; k < kGridRangeCells; ++k) {
    int cell = (k * grid_xy.y + c.y) * grid_xy.x + c.x;
    cells[2 * cell] = acc_a[k];
    cells[2 * cell + 1] = acc_b[k];
  }
}
