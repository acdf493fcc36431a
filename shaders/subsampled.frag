#version 450 core
// Spatially subsampled cross bilateral filter (FilterKind::Subsampled; Banterle et al. 2012): the
// bilateral-depth kernel evaluated at a few taps only, Poisson-disk offsets drawn from the spatial
// Gaussian (so the spatial weight is carried by the tap density) and rotated per pixel by a hash
// of the pixel. Each tap is weighted by its count (taps that rounded to the same pixel are merged)
// x the color x depth range weights: L_f = sum w L_u / sum w, Var[L_f] = sum w^2 Var / (sum w)^2,
// exact for the weights used. The tap table comes from subsampled_tap_table() in
// gl/cpu_reference.cpp, which cpu_subsampled() there uses too. Taps outside the image are left out.
#include "pass_formulas.h"

layout(binding = kUnitHv) uniform sampler2D hv_tex;     // rgb L_u, a Var[L_u] (kVarUnknown: n < 2; 0: all samples equal)
layout(binding = kUnitLv) uniform sampler2D lv_tex;     // rgb L_lv (only for skipping)
layout(binding = kUnitGuide) uniform sampler2D guide_tex;  // rgb range color, a distance
layout(binding = kUnitSurface) uniform sampler2D surface_tex;  // xyz shading normal (0: unknown), w roughness
uniform int taps_per_rotation;
uniform int rotations;
uniform float k_c;  // 1 / (2 sigma_c^2)
uniform float k_d;  // 1 / (2 sigma_d^2)
uniform float k_n;  // 1 / sigma_n^2, 0: no normal term (range_weights)
uniform float k_r;  // 1 / (2 sigma_r^2), 0: no roughness term
uniform int skip_case2;  // kSkipOff, kSkipOn or kSkipByHalves (skip_pixel)
layout(binding = kUnitHalfVariances) uniform sampler2D half_variances_tex;  // kSkipByHalves: (V_even, V_odd)
uniform float t;

layout(std430, binding = kBufferCounts) buffer Counter { uint filtered_pixels; };
// Rotation r's taps at [r * taps_per_rotation, ...): xy the offset, z the count (0 = padding).
layout(std430, binding = kBufferTaps) readonly buffer Taps { ivec4 taps[]; };
layout(location = 0) out vec4 out_filtered;  // rgb L_f, a Var[L_f] (kVarUnknown, kVarSkipped)

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  ivec2 size = textureSize(hv_tex, 0);
  if (skip_pixel(skip_case2, hv_tex, lv_tex, guide_tex, surface_tex, half_variances_tex, p, k_c, k_d, k_n, k_r, t)) {
    out_filtered = vec4(clean(texelFetch(hv_tex, p, 0).rgb), kVarSkipped);
    return;
  }
  atomicAdd(filtered_pixels, 1u);
  vec4 g_p = texelFetch(guide_tex, p, 0);
  vec4 s_p = texelFetch(surface_tex, p, 0);
  KernelSums sums = kernel_sums_zero();
  int first = subsampled_rotation(p, rotations) * taps_per_rotation;
  for (int i = 0; i < taps_per_rotation; ++i) {
    ivec4 tap = taps[first + i];
    if (tap.z == 0) break;
    ivec2 q = p + tap.xy;
    if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) continue;
    float w = float(tap.z) * range_weight(g_p, texelFetch(guide_tex, q, 0), s_p, texelFetch(surface_tex, q, 0), k_c, k_d, k_n, k_r);
    vec4 hv_q = texelFetch(hv_tex, q, 0);
    kernel_sums_add(sums, w, clean(hv_q.rgb), clean_var(hv_q.a));
  }
  // sums.w >= 1: the centre tap is in every rotation with range weight 1.
  out_filtered = vec4(kernel_sums_mean(sums), kernel_sums_variance(sums, 1.0));
}
