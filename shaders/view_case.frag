#version 450 core
// Explorer view of the blend case per pixel (kCase* and case_color in pass_formulas.h, which the
// explorer's legend uses too).
#include "pass_formulas.h"
layout(binding = 0) uniform sampler2D case_tex;  // r: case code (kCase*)
layout(location = 0) out vec4 out_display;

void main() {
  int code = int(texelFetch(case_tex, ivec2(gl_FragCoord.xy), 0).r + 0.5);
  out_display = vec4(case_color(code), 1.0);
}
