#version 450 core
// Overrides single pixels of the range frame with the path tracer's specular-chain results:
// one GL point per pixel, at the pixel's center (window row y = image row y).
layout(location = 0) in vec2 in_pixel;
layout(location = 1) in vec4 in_color_distance;
layout(location = 2) in vec4 in_surface;
uniform vec2 size;
out vec4 color_distance;
out vec4 surface;
void main() {
  color_distance = in_color_distance;
  surface = in_surface;
  gl_Position = vec4((in_pixel + 0.5) / size * 2.0 - 1.0, 0.0, 1.0);
  gl_PointSize = 1.0;
}
