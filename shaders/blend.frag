#version 450 core
// Blend of filtered and unfiltered HV light (docs/method.md section 3): s per pixel, L = L_lv + s L_u + (1-s) L_f.
#include "pass_formulas.h"

layout(binding = kUnitHv) uniform sampler2D hv_tex;        // rgb L_u, a Var[L_u]
layout(binding = kUnitLv) uniform sampler2D lv_tex;        // rgb L_lv, a the pixel's threshold factor (pixel_threshold)
layout(binding = kUnitFiltered) uniform sampler2D filtered_tex;  // rgb L_f, a Var[L_f] (or a sentinel)
layout(binding = kUnitGuide) uniform sampler2D guide_tex;   // rgb range color, a distance (pooling)
layout(binding = kUnitSurface) uniform sampler2D surface_tex;  // xyz shading normal (0: unknown), w roughness
layout(binding = kUnitCentreWeight) uniform sampler2D centre_weight_tex;  // r: the filter's centre weight w
// the bias guard's finding (b2, var_u) for the even half, then the odd (the same twice without halves)
layout(binding = kUnitGuardSums) uniform sampler2D guard_tex;
layout(binding = kUnitHalves) uniform sampler2D halves_tex;                 // split: rgb L_even, a n_even / n
layout(binding = kUnitHalfVariances) uniform sampler2D half_variances_tex;  // split: (V_even, V_odd)
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
uniform int split;       // 1: each half of the samples blended by the other's variance (blend_pixel_split)

layout(std430, binding = kBufferCounts) buffer CaseCounts { uint case_counts[kBlendCaseCount]; };
layout(location = 0) out vec4 out_final;  // rgb L, a s
layout(location = 1) out float out_case;

// The decision is shared::blend_pixel (pass_formulas.h), or blend_pixel_split of the halves; here
// only what it reads, and the neighbourhoods only where it compares variances.
void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  BlendTexels px;
  px.hv = texelFetch(hv_tex, p, 0);
  px.lv = texelFetch(lv_tex, p, 0);
  px.filtered = texelFetch(filtered_tex, p, 0);
  px.guide_distance = texelFetch(guide_tex, p, 0).a;
  BlendSwitches on = BlendSwitches(has_filtered != 0, has_guide != 0, bias_guard != 0, t, samples);
  PooledNeighbours pooled;
  pooled.sw = pooled.swv = pooled.centre = 0.0;
  // Settled before comparing variances (the halves share those cases): no neighbourhood is read.
  if (on.has_guide && blend_case_before_variances(px, on) == kCaseByVariances)
    pooled = pooled_neighbours(hv_tex, guide_tex, surface_tex, p, k_c, k_d, k_n, k_r);
  vec4 guard = on.bias_guard ? texelFetch(guard_tex, p, 0) : vec4(0.0);
  float w = has_centre_weight != 0 ? texelFetch(centre_weight_tex, p, 0).r : 0.0;
  BlendPixel b;
  if (split != 0) {
    vec4 halves = texelFetch(halves_tex, p, 0);
    vec2 variances = texelFetch(half_variances_tex, p, 0).rg;
    b = blend_pixel_split(px, halves, variances, on,
                          blend_variance_inputs(decision_texels(px, variances, 0), on, pooled, w, guard.xy),
                          blend_variance_inputs(decision_texels(px, variances, 1), on, pooled, w, guard.zw));
  } else {
    b = blend_pixel(px, on, blend_variance_inputs(px, on, pooled, w, guard.xy));
  }
  atomicAdd(case_counts[b.blend_case], 1u);
  out_final = vec4(b.radiance, b.s);
  out_case = float(b.blend_case);
}
