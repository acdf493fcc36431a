#version 450 core
// Cross bilateral filter (docs/method.md section 2) of the HV buffer guided by the range buffer, with the variance
// of the result: L_f = sum w L_u / sum w, Var[L_f] = sum w^2 Var[L_u] / (sum w)^2.
// extent (1,1): the full square kernel; (1,0) then (0,1): the separable variant's two 1D passes
// (the second filters the first's output, whose rows are independent, so its variance is exact).
#include "pass_formulas.h"

layout(binding = kUnitHv) uniform sampler2D hv_tex;     // rgb L_u, a Var[L_u] (kVarUnknown: n < 2; 0: all samples equal)
layout(binding = kUnitLv) uniform sampler2D lv_tex;     // rgb L_lv (only for skipping)
layout(binding = kUnitGuide) uniform sampler2D guide_tex;  // rgb range color, a distance
layout(binding = kUnitSurface) uniform sampler2D surface_tex;  // xyz shading normal (0: unknown), w roughness
layout(binding = kUnitSignal) uniform sampler2D signal_tex; // what is filtered: hv_tex, or the first 1D pass
uniform ivec2 extent;
uniform int final_pass;  // skipping and counting happen in the final pass only
uniform int radius;
uniform float k_s;   // 1 / (2 sigma_s^2)
uniform float k_c;   // 1 / (2 sigma_c^2)
uniform float k_d;   // 1 / (2 sigma_d^2), 0 for the color-only variant
uniform float k_n;  // 1 / sigma_n^2, 0: no normal term (range_weights)
uniform float k_r;  // 1 / (2 sigma_r^2), 0: no roughness term
uniform int skip_case2;  // kSkipOff, kSkipOn or kSkipByHalves (skip_pixel)
layout(binding = kUnitHalfVariances) uniform sampler2D half_variances_tex;  // kSkipByHalves: (V_even, V_odd)
uniform float t;

layout(std430, binding = kBufferCounts) buffer Counter { uint filtered_pixels; };
layout(location = 0) out vec4 out_filtered;  // rgb L_f, a Var[L_f] (kVarUnknown, kVarSkipped)
layout(location = 1) out float out_centre_weight;  // 1 / sum w: the pixel's own share of L_f

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  ivec2 size = textureSize(hv_tex, 0);
  vec4 hv_p = texelFetch(hv_tex, p, 0);
  vec3 lu_p = clean(hv_p.rgb);
  if (final_pass != 0 && skip_pixel(skip_case2, hv_tex, lv_tex, guide_tex, surface_tex, half_variances_tex, p, k_c, k_d, k_n, k_r, t)) {
    out_filtered = vec4(lu_p, kVarSkipped);
    out_centre_weight = 1.0;
    return;
  }
  if (final_pass != 0) atomicAdd(filtered_pixels, 1u);
  vec4 g_p = texelFetch(guide_tex, p, 0);
  vec4 s_p = texelFetch(surface_tex, p, 0);
  KernelSums sums = kernel_sums_zero();
  ivec2 lo = max(p - radius * extent, ivec2(0)), hi = min(p + radius * extent, size - 1);
  for (int qy = lo.y; qy <= hi.y; ++qy) {
    float dy2 = float((qy - p.y) * (qy - p.y));
    for (int qx = lo.x; qx <= hi.x; ++qx) {
      ivec2 q = ivec2(qx, qy);
      float e = (float((qx - p.x) * (qx - p.x)) + dy2) * k_s + range_exponent(g_p, texelFetch(guide_tex, q, 0), s_p, texelFetch(surface_tex, q, 0), k_c, k_d, k_n, k_r);
      vec4 hv_q = texelFetch(signal_tex, q, 0);
      kernel_sums_add(sums, exp(-e), clean(hv_q.rgb), clean_var(hv_q.a));
    }
  }
  // sums.w >= 1: the center's weight is exp(0).
  out_filtered = vec4(kernel_sums_mean(sums), kernel_sums_variance(sums, 1.0));
  out_centre_weight = 1.0 / sums.w;
}
