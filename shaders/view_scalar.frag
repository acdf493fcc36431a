#version 450 core
// Explorer view of one scalar channel in false color (turbo), on a linear or log10 scale between
// lo and hi. Used for Var[L_u], Var[L_f], the blend factor s and the depth, and for their legends
// (a ramp texture through the same shader, so legend and image always agree).
// Sentinels get fixed colors: kVarUnknown (n < 2, or no L_f yet) dark gray, kVarSkipped (the
// filter skipped a case-2 pixel) light gray, values >= background (depth: no surface) black.
#include "pass_formulas.h"
#include "view_colormap.glsl"

layout(binding = 0) uniform sampler2D source_tex;
uniform int channel;       // 0..3: r, g, b, a
uniform int log_scale;     // 1: position = (log10 v - log10 lo) / (log10 hi - log10 lo)
uniform float lo;
uniform float hi;
uniform int sentinels;     // 1: negative values are the variance sentinels above
uniform float background;  // values >= this are "nothing here" (black); <= 0: none

layout(location = 0) out vec4 out_display;

void main() {
  float v = texelFetch(source_tex, ivec2(gl_FragCoord.xy), 0)[channel];
  if (sentinels == 1 && v == kVarSkipped) { out_display = vec4(0.75, 0.75, 0.75, 1.0); return; }
  if (sentinels == 1 && (v < 0.0 || isnan(v))) { out_display = vec4(0.25, 0.25, 0.25, 1.0); return; }
  if (background > 0.0 && v >= background) { out_display = vec4(0.0, 0.0, 0.0, 1.0); return; }
  v = clean(v);
  float x;
  if (log_scale == 1) {
    float llo = log(max(lo, 1.0e-30)) / log(10.0), lhi = log(max(hi, 1.0e-30)) / log(10.0);
    x = v > 0.0 ? (log(v) / log(10.0) - llo) / max(lhi - llo, 1.0e-6) : 0.0;
  } else {
    x = (v - lo) / max(hi - lo, 1.0e-30);
  }
  out_display = vec4(turbo(x), 1.0);
}
