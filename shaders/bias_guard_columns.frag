#version 450 core
// The bias guard's sums, second pass: per pixel, the sum of the row sums (bias_guard_rows.frag) of
// the 5 pixels of its column window, the 5x5 sums the blend reads (bias_guard_sums_of).
#include "pass_formulas.h"

layout(binding = kUnitGuardSums) uniform sampler2D rows_tex;
layout(location = 0) out vec4 out_sums;

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  int height = textureSize(rows_tex, 0).y;
  vec4 sum = vec4(0.0);
  for (int dy = -kBiasGuardRadius; dy <= kBiasGuardRadius; ++dy) {
    ivec2 q = p + ivec2(0, dy);
    if (q.y >= 0 && q.y < height) sum += texelFetch(rows_tex, q, 0);
  }
  out_sums = sum;
}
