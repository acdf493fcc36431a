#version 450 core
// Albedo demodulation before the filter (gl/demodulation.h): the filter's inputs are
// demodulated_texel. The filter reads its LV input only for its case-2 skip; that input here
// carries the skip decision taken on the original buffers, so that every variant skips exactly the
// pixels it skips without demodulation: +kMaxInput makes u vanish (skip), -kMaxInput makes L_b = 0
// and u infinite (filter).
#include "pass_formulas.h"

layout(binding = kUnitHv) uniform sampler2D hv_tex;    // rgb L_u, a Var[L_u]
layout(binding = kUnitLv) uniform sampler2D lv_tex;    // rgb L_lv
layout(binding = kUnitGuide) uniform sampler2D guide_tex;  // rgb range color, a distance
layout(binding = kUnitSurface) uniform sampler2D surface_tex;  // xyz shading normal (0: unknown), w roughness
layout(binding = kUnitAlbedo) uniform sampler2D albedo_tex;  // rgb mean albedo
uniform float k_c;
uniform float k_d;
uniform float k_n;  // 1 / sigma_n^2, 0: no normal term (range_weights)
uniform float k_r;  // 1 / (2 sigma_r^2), 0: no roughness term
uniform float t;
uniform int skip_case2;  // kSkipOff, kSkipOn or kSkipByHalves (skip_pixel)
layout(binding = kUnitHalfVariances) uniform sampler2D half_variances_tex;  // kSkipByHalves: (V_even, V_odd)

layout(location = 0) out vec4 out_hv;  // demodulated_texel
layout(location = 1) out vec4 out_lv;  // the skip decision (see above)

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  out_hv = demodulated_texel(hv_tex, albedo_tex, p);
  bool skip = skip_pixel(skip_case2, hv_tex, lv_tex, guide_tex, surface_tex, half_variances_tex, p, k_c, k_d, k_n, k_r, t);
  out_lv = vec4(vec3(skip ? kMaxInput : -kMaxInput), 1.0);
}
