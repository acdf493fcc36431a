#version 450 core
// The bias guard's sums, first pass (docs/method.md section 3.7): per pixel, the sums of
// bias_guard_texel over its row from x - r to x + r, from x - r to x and from x to x + r
// (r = kBiasGuardRadius); bias_guard_columns.frag adds these up along the columns.
#include "pass_formulas.h"

layout(binding = kUnitHv) uniform sampler2D hv_tex;              // rgb L_u, a Var[L_u]
layout(binding = kUnitFiltered) uniform sampler2D filtered_tex;  // rgb L_f, a Var[L_f] (or a sentinel)
layout(location = 0) out vec4 out_full;
layout(location = 1) out vec4 out_low_x;
layout(location = 2) out vec4 out_high_x;

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  int width = textureSize(hv_tex, 0).x;
  vec4 low = vec4(0.0), high = vec4(0.0), centre = vec4(0.0);
  for (int dx = -kBiasGuardRadius; dx <= kBiasGuardRadius; ++dx) {
    ivec2 q = p + ivec2(dx, 0);
    if (q.x < 0 || q.x >= width) continue;
    vec4 c = bias_guard_texel(hv_tex, filtered_tex, q);
    if (dx < 0) low += c;
    if (dx > 0) high += c;
    if (dx == 0) centre = c;
  }
  out_full = low + centre + high;
  out_low_x = low + centre;
  out_high_x = centre + high;
}
