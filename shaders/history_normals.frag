#version 450 core
// The surface normal per pixel of a range buffer (shared::guide_normal), for the history's
// reprojection: computed once per guide instead of once per bilinear tap.
#include "history_formulas.h"

layout(binding = kUnitGuide) uniform sampler2D guide_tex;  // rgb range color, a distance
layout(binding = kUnitSignal) uniform sampler2D frame_tex; // the newest raster frame: a its specular flag
uniform vec3 cam_origin;
uniform mat3 cam_basis;
uniform float cam_half_height;
uniform float cam_aspect;
uniform int cam_orthographic;

layout(location = 0) out vec4 out_normal;  // xyz the unit normal, w 1 known, 0 background, -1 silhouette, -2 specular

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  vec2 size = vec2(textureSize(guide_tex, 0));
  ViewCamera c = ViewCamera(cam_origin, cam_basis, cam_half_height, cam_aspect, size, cam_orthographic != 0);
  out_normal = history_normal(guide_tex, texelFetch(frame_tex, p, 0).a, p, c);
}
