#version 450 core
// One pass of the edge-avoiding à-trous wavelet filter (Dammertz et al. 2010; FilterKind::Atrous):
// the 5x5 B3-spline kernel h at hole spacing `step_px` (1, 2, 4, ... over the passes), each tap
// weighted by h x the range weights of the cross bilateral filter (color, depth, surface; no
// spatial Gaussian beyond h) x the luminance edge stop on the signal itself
// (luminance_edge_exponent): L_f = sum w L / sum w, Var[L_f] = c sum w^2 Var / (sum w)^2 with the
// correction c for the correlation between the previous pass's pixels: atrous_variance_correction
// scaled by the share of the kernel the range weights keep (atrous_local_correction).
// Taps outside the image are left out; background pixels are left as they are (kBackgroundOnlyDistance).
// Mirrors atrous_pass() in gl/cpu_reference.cpp.
#include "pass_formulas.h"

layout(binding = kUnitHv) uniform sampler2D hv_tex;     // rgb L_u, a Var[L_u] (kVarUnknown: n < 2; 0: all samples equal)
layout(binding = kUnitLv) uniform sampler2D lv_tex;     // rgb L_lv (only for skipping)
layout(binding = kUnitGuide) uniform sampler2D guide_tex;  // rgb range color, a distance
layout(binding = kUnitSurface) uniform sampler2D surface_tex;  // xyz shading normal (0: unknown), w roughness
layout(binding = kUnitSignal) uniform sampler2D signal_tex; // what is filtered: hv_tex, or the previous pass
uniform int step_px;
uniform int final_pass;  // skipping and counting happen in the final pass only: later passes read every pixel
uniform float k_c;  // 1 / (2 sigma_c^2)
uniform float k_d;  // 1 / (2 sigma_d^2)
uniform float k_n;  // 1 / sigma_n^2, 0: no normal term (range_weights)
uniform float k_r;  // 1 / (2 sigma_r^2), 0: no roughness term
uniform float k_l;  // 1 / sigma_l, 0: no luminance edge stop (luminance_edge_exponent)
uniform int skip_case2;  // kSkipOff, kSkipOn or kSkipByHalves (skip_pixel)
layout(binding = kUnitHalfVariances) uniform sampler2D half_variances_tex;  // kSkipByHalves: (V_even, V_odd)
uniform float t;
uniform float variance_correction;  // atrous_variance_correction(pass)

layout(std430, binding = kBufferCounts) buffer Counter { uint filtered_pixels; };
layout(location = 0) out vec4 out_filtered;  // rgb L_f, a Var[L_f] (kVarUnknown, kVarSkipped)

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  ivec2 size = textureSize(hv_tex, 0);
  vec4 g_p = texelFetch(guide_tex, p, 0);
  if (g_p.a >= kBackgroundOnlyDistance) {
    vec4 own = texelFetch(signal_tex, p, 0);
    out_filtered = vec4(clean(own.rgb), final_pass != 0 ? kVarSkipped : own.a);
    return;
  }
  if (final_pass != 0 && skip_pixel(skip_case2, hv_tex, lv_tex, guide_tex, surface_tex, half_variances_tex, p, k_c, k_d, k_n, k_r, t)) {
    out_filtered = vec4(clean(texelFetch(hv_tex, p, 0).rgb), kVarSkipped);
    return;
  }
  if (final_pass != 0) atomicAdd(filtered_pixels, 1u);
  vec4 s_p = texelFetch(surface_tex, p, 0);
  vec4 signal_p = texelFetch(signal_tex, p, 0);
  vec3 l_p = clean(signal_p.rgb);
  float var_p = k_l > 0.0f ? edge_stop_variance(signal_tex, p) : kVarUnknown;
  KernelSums sums = kernel_sums_zero();
  float h_sum = 0.0;  // sum h over the taps inside the image
  for (int j = 0; j < 5; ++j) {
    int qy = p.y + (j - 2) * step_px;
    if (qy < 0 || qy >= size.y) continue;
    for (int i = 0; i < 5; ++i) {
      int qx = p.x + (i - 2) * step_px;
      if (qx < 0 || qx >= size.x) continue;
      ivec2 q = ivec2(qx, qy);
      h_sum += kB3[i] * kB3[j];
      vec4 s_q = texelFetch(signal_tex, q, 0);
      float w = kB3[i] * kB3[j] *
                exp(-range_exponent(g_p, texelFetch(guide_tex, q, 0), s_p, texelFetch(surface_tex, q, 0), k_c, k_d, k_n, k_r) -
                    luminance_edge_exponent(l_p, clean(s_q.rgb), var_p, k_l));
      kernel_sums_add(sums, w, clean(s_q.rgb), clean_var(s_q.a));
    }
  }
  // sums.w >= h(0,0) = 0.14: the center's range weight is 1.
  float correction = atrous_local_correction(variance_correction, float(sums.w) / h_sum);
  out_filtered = vec4(kernel_sums_mean(sums), kernel_sums_variance(sums, correction));
}
