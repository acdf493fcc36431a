#version 450 core
// The bias guard's sums, first pass (docs/method.md section 3.7): per pixel, the sum of
// bias_guard_texel over the 5 pixels of its row window; bias_guard_columns.frag adds 5 of these.
#include "pass_formulas.h"

layout(binding = kUnitHv) uniform sampler2D hv_tex;              // rgb L_u, a Var[L_u]
layout(binding = kUnitFiltered) uniform sampler2D filtered_tex;  // rgb L_f, a Var[L_f] (or a sentinel)
layout(location = 0) out vec4 out_sums;

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  int width = textureSize(hv_tex, 0).x;
  vec4 sum = vec4(0.0);
  for (int dx = -kBiasGuardRadius; dx <= kBiasGuardRadius; ++dx) {
    ivec2 q = p + ivec2(dx, 0);
    if (q.x >= 0 && q.x < width) sum += bias_guard_texel(hv_tex, filtered_tex, q);
  }
  out_sums = sum;
}
