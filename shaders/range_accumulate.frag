#version 450 core
// Running average of the jittered range frames: guide = rgb range color, a distance; surface = xyz
// shading normal, w roughness (averaged like the colour: unit length only where every frame saw
// the same surface). Also the
// per-pixel change of this step (max over color channels and relative distance), reduced on the
// GPU to decide convergence.
layout(binding = 0) uniform sampler2D frame_color;     // rgb range color, a flag
layout(binding = 1) uniform sampler2D frame_distance;  // r distance
layout(binding = 2) uniform sampler2D previous;        // accumulated guide so far
layout(binding = 3) uniform sampler2D frame_surface;   // xyz normal, w roughness
layout(binding = 4) uniform sampler2D previous_surface;
uniform int count;  // frames including this one (>= 1)

layout(location = 0) out vec4 out_guide;
layout(location = 1) out float out_change;
layout(location = 2) out vec4 out_surface;

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  vec4 cur = vec4(texelFetch(frame_color, p, 0).rgb, texelFetch(frame_distance, p, 0).r);
  vec4 cur_surface = texelFetch(frame_surface, p, 0);
  if (count <= 1) {
    out_surface = cur_surface;
    out_guide = cur;
    out_change = 1.0;
    return;
  }
  vec4 prev = texelFetch(previous, p, 0);
  vec4 prev_surface = texelFetch(previous_surface, p, 0);
  out_surface = prev_surface + (cur_surface - prev_surface) / float(count);
  vec4 next = prev + (cur - prev) / float(count);
  vec4 d = abs(next - prev);
  out_guide = next;
  out_change = max(max(d.r, max(d.g, d.b)), d.a / max(next.a, 1e-3));
}
