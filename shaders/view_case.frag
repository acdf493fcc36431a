#version 450 core
// Explorer view of the blend case per pixel (kCase* in pass_formulas.h). Keep the colors in step
// with kCaseStyles in app/explorer_views.cpp (the legend).
#include "pass_formulas.h"
layout(binding = 0) uniform sampler2D case_tex;  // r: BlendCase code
layout(location = 0) out vec4 out_display;

const vec3 kColors[kBlendCaseCount] = vec3[kBlendCaseCount](
    vec3(0.35, 0.35, 0.35),   // 0: no L_f yet (s = 1)
    vec3(0.90, 0.20, 0.15),   // 1: D < 0, filtered only (s = 0)
    vec3(0.20, 0.75, 0.25),   // 2: u <= t, unfiltered (s = 1)
    vec3(0.20, 0.45, 0.95),   // 3: mixed (0 < s < 1)
    vec3(0.85, 0.30, 0.85));  // 4: n < 2, variance unknown (s = 0)

void main() {
  int code = int(texelFetch(case_tex, ivec2(gl_FragCoord.xy), 0).r + 0.5);
  out_display = vec4(code >= 0 && code < kBlendCaseCount ? kColors[code] : vec3(1.0, 1.0, 0.0), 1.0);
}
