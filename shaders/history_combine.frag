#version 450 core
// The reprojected history beside the fresh samples (docs/method.md section 4.1):
// shared::combine_history per pixel. Writes the inputs the filter and blend then read, and the
// state the next camera move reprojects.
#include "history_formulas.h"

layout(binding = kUnitHv) uniform sampler2D hv_tex;              // fresh: rgb L_u, a Var[L_u]
layout(binding = kUnitLv) uniform sampler2D lv_tex;              // fresh: rgb L_lv, a threshold factor
layout(binding = kUnitHistoryLv) uniform sampler2D history_lv_tex;  // rgb L_lv, a samples held
layout(binding = kUnitHistoryHv) uniform sampler2D history_hv_tex;  // rgb L_u, a Var[L_u]
uniform float samples;      // n, the fresh samples of every pixel
uniform int has_history;    // 0: the fresh samples alone (the state of a view without history)

layout(location = 0) out vec4 out_lv;     // rgb L_lv, a the fresh texel's threshold factor
layout(location = 1) out vec4 out_hv;     // rgb L_u, a Var[L_u]
layout(location = 2) out vec4 out_state;  // rgb L_lv, a the samples it counts as (for the next move)
layout(location = 3) out float out_weight;  // the history's weight alpha

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  vec4 lv = texelFetch(lv_tex, p, 0);
  vec4 hv = texelFetch(hv_tex, p, 0);
  HistorySample h = history_none(kHistoryNone);
  if (has_history != 0) {
    vec4 hlv = texelFetch(history_lv_tex, p, 0);
    vec4 hhv = texelFetch(history_hv_tex, p, 0);
    h.lv = vec3(hlv);
    h.count = hlv.a;
    h.hv = vec3(hhv);
    h.var = hhv.a;
  }
  HistoryBlend b = combine_history(vec3(lv), vec3(hv), hv.a, samples, h);
  out_lv = vec4(b.lv, lv.a);
  out_hv = vec4(b.hv, b.var);
  out_state = vec4(b.lv, b.count);
  out_weight = b.weight;
}
