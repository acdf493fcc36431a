#version 450 core
// Blend of filtered and unfiltered HV light (docs/method.md section 3): s per pixel, L = L_lv + s L_u + (1-s) L_f.
#include "pass_formulas.h"

layout(binding = kUnitHv) uniform sampler2D hv_tex;        // rgb L_u, a Var[L_u]
layout(binding = kUnitLv) uniform sampler2D lv_tex;        // rgb L_lv, a the pixel's threshold factor (pixel_threshold)
layout(binding = kUnitFiltered) uniform sampler2D filtered_tex;  // rgb L_f, a Var[L_f] (or a sentinel)
layout(binding = kUnitGuide) uniform sampler2D guide_tex;   // rgb range color, a distance (pooling)
layout(binding = kUnitSurface) uniform sampler2D surface_tex;  // xyz shading normal (0: unknown), w roughness
layout(binding = kUnitCentreWeight) uniform sampler2D centre_weight_tex;  // r: the filter's centre weight w
layout(binding = kUnitGuardSums) uniform sampler2D guard_tex;  // rg: the bias guard's finding, b2 and var_u (bias_guard: 1)
uniform int has_filtered;
uniform int has_centre_weight;  // 0: Cov[L_u, L_f] not known, left out (w = 0)
uniform int has_guide;  // 0: u from the pixel's own variance only
uniform float k_c;      // range weights of the variance pooling (the filter's)
uniform float k_d;
uniform float k_n;  // 1 / sigma_n^2, 0: no normal term (range_weights)
uniform float k_r;  // 1 / (2 sigma_r^2), 0: no roughness term
uniform float t;         // times the pixel's factor: pixel_threshold
uniform float samples;   // the run's n, for the zero-variance rule's decay (pixel_samples); 0: unknown
uniform int bias_guard;  // 1: raise s where L_f is measurably biased (bias_guard_factor)

layout(std430, binding = kBufferCounts) buffer CaseCounts { uint case_counts[kBlendCaseCount]; };
layout(location = 0) out vec4 out_final;  // rgb L, a s
layout(location = 1) out float out_case;

// The decision is shared::blend_pixel (pass_formulas.h); here only what it reads, and the
// neighbourhoods only where it compares variances.
void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  BlendTexels px;
  px.hv = texelFetch(hv_tex, p, 0);
  px.lv = texelFetch(lv_tex, p, 0);
  px.filtered = texelFetch(filtered_tex, p, 0);
  px.guide_distance = texelFetch(guide_tex, p, 0).a;
  BlendSwitches on = BlendSwitches(has_filtered != 0, has_guide != 0, bias_guard != 0, t, samples);
  BlendVarianceInputs v = blend_variance_inputs_none();
  if (blend_compares_variances(px, on)) {
    if (on.has_guide) v.var_u_pooled = pooled_var_u(hv_tex, guide_tex, surface_tex, p, k_c, k_d, k_n, k_r);
    if (has_centre_weight != 0) v.centre_weight = texelFetch(centre_weight_tex, p, 0).r;
    if (on.bias_guard) {
      vec4 g = texelFetch(guard_tex, p, 0);
      v.guard.b2 = g.x;
      v.guard.var_u = g.y;
    }
  }
  BlendPixel b = blend_pixel(px, on, v);
  atomicAdd(case_counts[b.blend_case], 1u);
  out_final = vec4(b.radiance, b.s);
  out_case = float(b.blend_case);
}
