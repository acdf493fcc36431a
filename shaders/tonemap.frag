#version 450 core
// Reinhard's global photographic operator (key a, log-average luminance, optional white point),
// then the sRGB transfer curve. Output: display values in [0,1].
#include "pass_formulas.h"
#include "tonemap_formulas.h"

layout(binding = 0) uniform sampler2D hdr_tex;  // rgb linear radiance
layout(std430, binding = 2) buffer Result { float result[]; };  // reduce.comp: sum log(delta+Y), count
uniform float key;
uniform float white;        // in key-scaled luminance; <= 0: none
uniform float log_average;  // > 0: fixed, else exp(result[0] / result[1])

layout(location = 0) out vec4 out_display;

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  vec3 c = clamp(clean(texelFetch(hdr_tex, p, 0).rgb), vec3(0.0), vec3(kMaxInput));
  float lavg = log_average > 0.0 ? log_average : exp(result[0] / max(result[1], 1.0));
  float k = key / max(lavg, 1.0e-30);
  float scale = reinhard_scale(k, luminance(c), white);
  vec3 d = clamp(c * scale, vec3(0.0), vec3(1.0));
  out_display = vec4(srgb_encode(d.r), srgb_encode(d.g), srgb_encode(d.b), 1.0);
}
