#version 450 core
// Bilateral grid, step 4: slice. Each pixel interpolates the blurred grid trilinearly at its own
// (x / cell_s, y / cell_s, z): the value sums with the weights a, the squared-weight sums with a^2.
// L_f = sum a / sum count; Var[L_f] = c(a_x) c(a_y) c_z (sum w^2 Var + sum w^2 (unknown) x mean
// known Var) / (sum w)^2, c = grid_interpolation_correction and c_z = grid_range_correction
// (pass_formulas.h) for the correlation of the interpolated cells along the spatial and range axes.
// Case-2 pixels are skipped as in the other variants.
// Mirrors slice() in gl/grid_reference.cpp.
#include "pass_formulas.h"
#include "grid_common.glsl"

layout(binding = kUnitHv) uniform sampler2D hv_tex;     // rgb L_u, a Var[L_u]
layout(binding = kUnitLv) uniform sampler2D lv_tex;     // rgb L_lv (only for skipping)
layout(binding = kUnitGuide) uniform sampler2D guide_tex;  // rgb range color, a distance
layout(binding = kUnitSurface) uniform sampler2D surface_tex;  // xyz shading normal (0: unknown), w roughness
layout(std430, binding = kBufferGrid) readonly buffer Grid { vec4 cells[]; };
layout(std430, binding = kBufferCounts) buffer Counter { uint filtered_pixels; };
uniform ivec2 grid_xy;
uniform float inv_cell_s;
uniform float min_cell_z;  // grid_min_cell_z(sigma_c)
uniform float k_c;  // 1 / (2 sigma_c^2), for skipping
uniform float k_d;  // 1 / (2 sigma_d^2), for skipping
uniform float k_n;  // 1 / sigma_n^2, 0: no normal term (range_weights)
uniform float k_r;  // 1 / (2 sigma_r^2), 0: no roughness term
uniform int skip_case2;  // kSkipOff, kSkipOn or kSkipByHalves (skip_pixel)
layout(binding = kUnitHalfVariances) uniform sampler2D half_variances_tex;  // kSkipByHalves: (V_even, V_odd)
uniform float t;

layout(location = 0) out vec4 out_filtered;  // rgb L_f, a Var[L_f] (kVarUnknown, kVarSkipped)
layout(location = 1) out float out_centre_weight;  // the pixel's own share of L_f (1 where skipped)

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  if (skip_pixel(skip_case2, hv_tex, lv_tex, guide_tex, surface_tex, half_variances_tex, p, k_c, k_d, k_n, k_r, t)) {
    out_filtered = vec4(clean(texelFetch(hv_tex, p, 0).rgb), kVarSkipped);
    out_centre_weight = 1.0;
    return;
  }
  atomicAdd(filtered_pixels, 1u);
  precise vec2 uv = vec2(p) * inv_cell_s;
  float z = grid_z(guide_luminance(texelFetch(guide_tex, p, 0)), min_cell_z);
  ivec3 c0 = ivec3(ivec2(floor(uv)), min(int(floor(z)), kGridRangeCells - 2));
  vec3 frac = clamp(vec3(uv, z) - vec3(c0), 0.0, 1.0);
  ivec3 own = ivec3(nearest_cell(uv.x), nearest_cell(uv.y), clamp(nearest_cell(z), 0, kGridRangeCells - 1));
  vec4 a = vec4(0.0), b = vec4(0.0);
  float own_weight = 0.0;
  for (int dz = 0; dz < 2; ++dz)
    for (int dy = 0; dy < 2; ++dy)
      for (int dx = 0; dx < 2; ++dx) {
        float w = (dx == 1 ? frac.x : 1.0 - frac.x) * (dy == 1 ? frac.y : 1.0 - frac.y) *
                  (dz == 1 ? frac.z : 1.0 - frac.z);
        int cell = ((c0.z + dz) * grid_xy.y + c0.y + dy) * grid_xy.x + c0.x + dx;
        a += w * cells[2 * cell];
        own_weight += w * grid_blur_tap(c0.x + dx - own.x) * grid_blur_tap(c0.y + dy - own.y) * grid_blur_tap(c0.z + dz - own.z);
        b += vec4(w * w, w * w, w, w) * cells[2 * cell + 1];
      }
  // a.w > 0: the pixel's own nearest cell is a corner with interpolation weight >= 1/2 per axis.
  float correction = grid_interpolation_correction(frac.x) * grid_interpolation_correction(frac.y) *
                     grid_range_correction(frac.z, c0.z, own.z);
  // b: sum w^2 Var (known), sum w^2 (unknown), sum w and sum w Var (known).
  out_filtered = vec4(a.rgb / a.w, propagated_variance(a.w, b.x, b.y, b.z, b.w, correction));
  out_centre_weight = own_weight / a.w;
}
