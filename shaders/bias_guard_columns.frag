#version 450 core
// The bias guard's second pass: per pixel, the row sums (bias_guard_rows.frag) added along its
// column into the 5x5 window's sums and its four half windows' (y from -r to 0 and from 0 to r,
// x from -r to 0 and from 0 to r), and the guard's finding from them (bias_guard_estimate): the
// squared bias and the variance it is traded against, which the blend reads.
#include "pass_formulas.h"

layout(binding = kUnitGuardSums) uniform sampler2D rows_tex;          // row sums, x in [-r, r]
layout(binding = kUnitGuardRowsLowX) uniform sampler2D low_x_tex;     // x in [-r, 0]
layout(binding = kUnitGuardRowsHighX) uniform sampler2D high_x_tex;   // x in [0, r]
layout(binding = kUnitHv) uniform sampler2D hv_tex;                   // the pixel's own window
layout(binding = kUnitFiltered) uniform sampler2D filtered_tex;
layout(binding = kUnitHalves) uniform sampler2D halves_tex;                 // split: rgb L_even, a n_even / n
layout(binding = kUnitHalfVariances) uniform sampler2D half_variances_tex;  // split: (V_even, V_odd)
uniform int split;  // 1: one finding per half, its windows reading the other half at the pixel (section 3.8)
// (b2, var_u) of BiasGuardEstimate; split: the even half's, then the odd half's, else the same twice
layout(location = 0) out vec4 out_estimate;

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  int height = textureSize(rows_tex, 0).y;
  vec4 low_y = vec4(0.0), high_y = vec4(0.0), centre = vec4(0.0), low_x = vec4(0.0), high_x = vec4(0.0);
  for (int dy = -kBiasGuardRadius; dy <= kBiasGuardRadius; ++dy) {
    ivec2 q = p + ivec2(0, dy);
    if (q.y < 0 || q.y >= height) continue;
    vec4 row = texelFetch(rows_tex, q, 0);
    if (dy < 0) low_y += row;
    if (dy > 0) high_y += row;
    if (dy == 0) centre = row;
    low_x += texelFetch(low_x_tex, q, 0);
    high_x += texelFetch(high_x_tex, q, 0);
  }
  vec4 full = low_y + centre + high_y;
  if (split == 0) {
    BiasGuardEstimate e = bias_guard_estimate(full, low_y + centre, centre + high_y, low_x, high_x,
                                              bias_guard_texel(hv_tex, filtered_tex, p));
    out_estimate = vec4(e.b2, e.var_u, e.b2, e.var_u);
    return;
  }
  vec4 hv = texelFetch(hv_tex, p, 0), f = texelFetch(filtered_tex, p, 0), halves = texelFetch(halves_tex, p, 0);
  vec2 variances = texelFetch(half_variances_tex, p, 0).rg;
  vec4 own = bias_guard_texel_of(hv, f);
  BiasGuardEstimate even = half_guard_estimate(full, low_y + centre, centre + high_y, low_x, high_x, own,
                                               bias_guard_texel_of(half_texel(hv, halves, variances, 1), f));
  BiasGuardEstimate odd = half_guard_estimate(full, low_y + centre, centre + high_y, low_x, high_x, own,
                                              bias_guard_texel_of(half_texel(hv, halves, variances, 0), f));
  out_estimate = vec4(even.b2, even.var_u, odd.b2, odd.var_u);
}
