#version 450 core
// Range buffer where the camera ray escapes to the environment: its radiance, compressed to
// [0, 1) per channel by L / (1 + L) (range_environment_color in range_formulas.h), so that a bright
// softbox and a dark backdrop get different range colors and the filter does not mix them. The
// distance stays the background's. Drawn before the geometry, which overwrites it where it is hit.
#include "range_formulas.h"
layout(binding = 0) uniform sampler2D environment_tex;  // equirect linear RGB radiance
uniform mat4 inverse_view_projection;                   // of the jittered raster camera
uniform vec2 size;
uniform float strength;
uniform float background_distance;

layout(location = 0) out vec4 out_color;  // rgb range color, a specular flag (0)
layout(location = 1) out float out_distance;
layout(location = 2) out vec4 out_surface;  // no surface: normal 0 (unknown), roughness 0

const float kPi = 3.14159265358979;

// Same convention as equirect_uv() in pathtracer/lights.cpp.
vec2 equirect_uv(vec3 d) {
  float u = 0.5 + atan(d.x, -d.z) * (0.5 / kPi);
  float v = acos(clamp(d.y, -1.0, 1.0)) / kPi;
  return vec2(u - floor(u), v);
}

void main() {
  vec2 ndc = gl_FragCoord.xy / size * 2.0 - 1.0;
  vec4 near = inverse_view_projection * vec4(ndc, -1.0, 1.0);
  vec4 far = inverse_view_projection * vec4(ndc, 1.0, 1.0);
  vec3 direction = normalize(far.xyz / far.w - near.xyz / near.w);
  vec3 radiance = texture(environment_tex, equirect_uv(direction)).rgb * strength;
  out_color = vec4(range_environment_color(radiance), 0.0);
  out_distance = background_distance;
  out_surface = vec4(0.0);
}
