#version 450 core
// Blend of filtered and unfiltered HV light (docs/method.md section 3): s per pixel, L = L_lv + s L_u + (1-s) L_f.
#include "pass_formulas.h"

layout(binding = kUnitHv) uniform sampler2D hv_tex;        // rgb L_u, a Var[L_u]
layout(binding = kUnitLv) uniform sampler2D lv_tex;        // rgb L_lv, a the pixel's threshold factor (pixel_threshold)
layout(binding = kUnitFiltered) uniform sampler2D filtered_tex;  // rgb L_f, a Var[L_f] (or a sentinel)
layout(binding = kUnitGuide) uniform sampler2D guide_tex;   // rgb range color, a distance (pooling)
layout(binding = kUnitCentreWeight) uniform sampler2D centre_weight_tex;  // r: the filter's centre weight w
layout(binding = kUnitGuardSums) uniform sampler2D guard_tex;  // rg: the bias guard's finding, b2 and var_u (bias_guard: 1)
uniform int has_filtered;
uniform int has_centre_weight;  // 0: Cov[L_u, L_f] not known, left out (w = 0)
uniform int has_guide;  // 0: u from the pixel's own variance only
uniform float k_c;      // range weights of the variance pooling (the filter's)
uniform float k_d;
uniform float t;         // times the pixel's factor: pixel_threshold
uniform int bias_guard;  // 1: raise s where L_f is measurably biased (bias_guard_factor)

layout(std430, binding = kBufferCounts) buffer CaseCounts { uint case_counts[kBlendCaseCount]; };
layout(location = 0) out vec4 out_final;  // rgb L, a s
layout(location = 1) out float out_case;

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  vec4 hv = texelFetch(hv_tex, p, 0);
  vec3 lu = clean(hv.rgb);
  vec4 lv_texel = texelFetch(lv_tex, p, 0);
  vec3 lv = clean(lv_texel.rgb);
  vec3 lf = lu;
  float s = 1.0;
  int blend_case = kCaseNoFiltered;
  if (has_filtered != 0) {
    vec4 fv = texelFetch(filtered_tex, p, 0);
    lf = clean(fv.rgb);
    float vu = clean_var(hv.a);
    if (fv.a < kVarSkippedBelow) {
      s = 1.0;
      blend_case = kCaseUnfiltered;  // skipped by the filter
    } else if (has_guide != 0 && lu == vec3(0.0) && texelFetch(guide_tex, p, 0).a >= kBackgroundDistanceMin) {
      s = 1.0;
      blend_case = kCaseUnfiltered;  // the background rule (kBackgroundDistanceMin): no HV light to miss
    } else if (vu < 0.0) {
      s = 0.0;
      blend_case = kCaseUnknownVar;  // n < 2
    } else {
      float vf = max(clean_var(fv.a), 0.0);
      float lb = max(luminance(lf) + luminance(lv), 0.0);
      if (has_guide != 0) vu = pooled_var_u(hv_tex, guide_tex, p, k_c, k_d);
      float u = vu > 0.0 ? relative_variance(vu, lb) : zero_variance_u(luminance(lf), lb);
      float w = has_centre_weight != 0 ? texelFetch(centre_weight_tex, p, 0).r : 0.0;
      float f = relative_variance(vf, lb);
      s = blend_factor_covariance(u, f, pixel_threshold(t, lv_texel), w, blend_case);
      if (bias_guard != 0) {
        vec2 g = texelFetch(guard_tex, p, 0).rg;
        BiasGuardEstimate e;
        e.b2 = g.x;
        e.var_u = g.y;
        s = guarded_blend_factor(e, s, u, f, w, lb, blend_case);
      }
    }
  }
  atomicAdd(case_counts[blend_case], 1u);
  out_final = vec4(clean(lv + s * lu + (1.0 - s) * lf), s);
  out_case = float(blend_case);
}
