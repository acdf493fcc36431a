#version 450 core
// Explorer split view: the left display texture left of the divider, the right one right of it,
// and a one-pixel divider line.
layout(binding = 0) uniform sampler2D left_tex;
layout(binding = 1) uniform sampler2D right_tex;
uniform float divider;  // x in pixels

layout(location = 0) out vec4 out_display;

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  if (p.x == int(divider)) { out_display = vec4(1.0, 1.0, 1.0, 1.0); return; }
  out_display = p.x < int(divider) ? texelFetch(left_tex, p, 0) : texelFetch(right_tex, p, 0);
}
