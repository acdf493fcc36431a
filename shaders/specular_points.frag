#version 450 core
in vec4 color_distance;
layout(location = 0) out vec4 out_color;  // the flag stays 1
layout(location = 1) out float out_distance;
void main() {
  out_color = vec4(color_distance.rgb, 1.0);
  out_distance = color_distance.a;
}
