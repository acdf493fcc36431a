#version 450 core
// Reprojection of the previous view's estimate into the new view (docs/method.md section 4.1):
// shared::reproject_history per pixel, through the new guide's distance and both cameras.
#include "history_formulas.h"

layout(binding = kUnitHistoryLv) uniform sampler2D previous_lv_tex;       // rgb L_lv, a samples held
layout(binding = kUnitHistoryHv) uniform sampler2D previous_hv_tex;       // rgb L_u, a Var[L_u]
layout(binding = kUnitHistoryGuide) uniform sampler2D previous_guide_tex; // the previous view's guide
layout(binding = kUnitHistoryNormals) uniform sampler2D previous_normals_tex;  // its guide_normal
layout(binding = kUnitGuide) uniform sampler2D guide_tex;                 // the new view's guide
layout(binding = kUnitNormals) uniform sampler2D normals_tex;             // its guide_normal
// The cameras as ViewCamera: origin, rotation, tan(yfov / 2) or ymag, aspect, orthographic.
uniform vec3 now_origin;
uniform mat3 now_basis;
uniform float now_half_height;
uniform float now_aspect;
uniform int now_orthographic;
uniform vec3 before_origin;
uniform mat3 before_basis;
uniform float before_half_height;
uniform float before_aspect;
uniform int before_orthographic;

layout(location = 0) out vec4 out_lv;       // rgb L_lv, a samples held (0: no history)
layout(location = 1) out vec4 out_hv;       // rgb L_u, a Var[L_u]
layout(location = 2) out float out_outcome; // kHistory*

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  vec2 size = vec2(textureSize(guide_tex, 0));
  ViewCamera now = ViewCamera(now_origin, now_basis, now_half_height, now_aspect, size, now_orthographic != 0);
  ViewCamera before = ViewCamera(before_origin, before_basis, before_half_height, before_aspect, size,
                                 before_orthographic != 0);
  HistorySample h = reproject_history(previous_lv_tex, previous_hv_tex, previous_guide_tex, previous_normals_tex,
                                      guide_tex, normals_tex, p, now, before);
  out_lv = vec4(h.lv, h.count);
  out_hv = vec4(h.hv, h.var);
  out_outcome = float(h.outcome);
}
