#version 450 core
// G-buffer/range pass: world-space meshes (the scene is flattened at load) through the path
// tracer's exact camera (camera_view_matrix / camera_projection_matrix with the frame's jitter).
layout(location = 0) in vec3 in_position;
layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec2 in_uv0;
layout(location = 3) in vec2 in_uv1;
layout(location = 4) in vec4 in_color;
layout(location = 5) in vec4 in_tangent;  // xyz + handedness w; (0, 0, 0, 1) without a normal map
uniform mat4 view_projection;

out vec3 world_position;
out vec3 world_normal;
out vec2 uv0;
out vec2 uv1;
out vec4 vertex_color;
out vec4 world_tangent;

void main() {
  world_position = in_position;
  world_normal = in_normal;
  uv0 = in_uv0;
  uv1 = in_uv1;
  vertex_color = in_color;
  world_tangent = in_tangent;
  gl_Position = view_projection * vec4(in_position, 1.0);
}
