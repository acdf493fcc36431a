#version 450 core
// Albedo remodulation after the filter (gl/demodulation.h): L_f = a L_f', Var[L_f] = Y(a)^2
// Var[L_f'] with the demodulation factor a of the pixel; the sentinels (unknown, skipped) are kept.
#include "pass_formulas.h"

layout(binding = kUnitFiltered) uniform sampler2D filtered_tex;  // rgb L_f', a Var[L_f'] or a sentinel
layout(binding = kUnitAlbedo) uniform sampler2D albedo_tex;  // rgb mean albedo

layout(location = 0) out vec4 out_filtered;  // rgb L_f, a Var[L_f] or the sentinel

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  vec4 f = texelFetch(filtered_tex, p, 0);
  vec3 a = demodulation_factor(texelFetch(albedo_tex, p, 0).rgb);
  float k = luminance(a);
  out_filtered = vec4(clean(a * clean(f.rgb)), remodulated_var(f.a, k));
}
