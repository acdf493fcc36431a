#version 450 core
in vec4 color_distance;
in vec4 surface;
layout(location = 0) out vec4 out_color;  // the flag stays 1
layout(location = 1) out float out_distance;
layout(location = 2) out vec4 out_surface;  // the chain end's normal and roughness (0: escaped)
void main() {
  out_color = vec4(color_distance.rgb, 1.0);
  out_distance = color_distance.a;
  out_surface = surface;
}
