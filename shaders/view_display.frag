#version 450 core
// Explorer view of an RGB texture: display values copied as they are (tone-mapped buffers), or
// linear values through the sRGB curve only (the range color: an albedo, not a radiance).
#include "pass_formulas.h"

layout(binding = 0) uniform sampler2D source_tex;
uniform int encode_srgb;  // 1: linear in, sRGB out

layout(location = 0) out vec4 out_display;

float srgb(float v) {
  v = clamp(v, 0.0, 1.0);
  return v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1.0 / 2.4) - 0.055;
}

void main() {
  vec3 c = clean(texelFetch(source_tex, ivec2(gl_FragCoord.xy), 0).rgb);
  if (encode_srgb == 1) c = vec3(srgb(c.r), srgb(c.g), srgb(c.b));
  out_display = vec4(clamp(c, 0.0, 1.0), 1.0);
}
