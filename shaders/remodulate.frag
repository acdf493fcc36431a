#version 450 core
// Albedo remodulation after the filter (gl/demodulation.h): remodulated_texel.
#include "pass_formulas.h"

layout(binding = kUnitFiltered) uniform sampler2D filtered_tex;  // rgb L_f', a Var[L_f'] or a sentinel
layout(binding = kUnitAlbedo) uniform sampler2D albedo_tex;  // rgb mean albedo

layout(location = 0) out vec4 out_filtered;  // rgb L_f, a Var[L_f] or the sentinel

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  vec4 f = texelFetch(filtered_tex, p, 0);
  out_filtered = remodulated_texel(f, texelFetch(albedo_tex, p, 0).rgb);
}
