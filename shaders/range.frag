#version 450 core
// Range color = range_shading(albedo, interpolated normal, to_viewer) (range_formulas.h), albedo =
// base color factor x base color texture x vertex color (linear); the camera ray's length; the
// perfectly-specular flag; the surface: the shading normal (the normal map applied through the
// tangent frame, as EmbreeScene::map_normal does) and the roughness (factor x the
// metallic-roughness texture's G, as eval_material). Alpha-mask cutouts are discarded; nothing is
// culled.
#include "range_formulas.h"
in vec3 world_position;
in vec3 world_normal;
in vec2 uv0;
in vec2 uv1;
in vec4 vertex_color;
in vec4 world_tangent;

layout(binding = 0) uniform sampler2D base_color_tex;  // 1x1 white when the material has none
uniform vec4 base_color;
uniform int texcoord;      // 0 or 1
uniform mat3 uv_transform; // KHR_texture_transform, applied to (u, v, 1)
layout(binding = 1) uniform sampler2D normal_tex;     // tangent-space normal map; 1x1 white when none
uniform int normal_map;        // 1: the material has one (and the mesh tangents)
uniform float normal_scale;
uniform int normal_texcoord;
uniform mat3 normal_uv_transform;
layout(binding = 2) uniform sampler2D roughness_tex;  // metallic-roughness texture (G); 1x1 white when none
uniform float roughness;
uniform int roughness_texcoord;
uniform mat3 roughness_uv_transform;
uniform int alpha_mask;
uniform float alpha_cutoff;
uniform int double_sided;
uniform float specular;    // 1: perfectly specular material
uniform vec3 camera_position;
uniform vec3 camera_forward;  // unit view direction
uniform int orthographic;     // 1: parallel rays along camera_forward from the camera's plane

layout(location = 0) out vec4 out_color;  // rgb range color, a specular flag
layout(location = 1) out float out_distance;
layout(location = 2) out vec4 out_surface;  // xyz shading normal, w roughness

void main() {
  vec2 uv = (uv_transform * vec3(texcoord == 1 ? uv1 : uv0, 1.0)).xy;
  vec4 albedo = base_color * texture(base_color_tex, uv) * vertex_color;
  if (alpha_mask != 0 && !(albedo.a >= alpha_cutoff)) discard;
  // The distance the path tracer's camera ray travels: to the eye, or to the orthographic plane.
  vec3 to_camera = camera_position - world_position;
  float distance = orthographic != 0 ? dot(-to_camera, camera_forward) : length(to_camera);
  vec3 v = orthographic != 0 ? -camera_forward : to_camera / max(distance, 1e-30);
  vec3 n = normalize(world_normal);
  vec3 shading = n;
  if (normal_map != 0) {
    vec3 t = world_tangent.xyz - n * dot(world_tangent.xyz, n);
    float tl = length(t);
    if (tl > 1e-8) {
      t /= tl;
      vec3 b = cross(n, t) * (world_tangent.w < 0.0 ? -1.0 : 1.0);
      vec2 nuv = (normal_uv_transform * vec3(normal_texcoord == 1 ? uv1 : uv0, 1.0)).xy;
      vec3 m = texture(normal_tex, nuv).rgb * 2.0 - 1.0;
      m.xy *= normal_scale;
      vec3 mapped = t * m.x + b * m.y + n * m.z;
      float ml = length(mapped);
      if (ml > 1e-8) shading = mapped / ml;
    }
  }
  // As the path tracer: only double-sided materials flip the normal toward the viewer.
  if (double_sided != 0 && dot(n, v) < 0.0) {
    n = -n;
    shading = -shading;
  }
  out_color = vec4(range_shading(albedo.rgb, n, v), specular);
  out_distance = distance;
  vec2 ruv = (roughness_uv_transform * vec3(roughness_texcoord == 1 ? uv1 : uv0, 1.0)).xy;
  out_surface = vec4(shading, clamp(roughness * texture(roughness_tex, ruv).g, 0.0, 1.0));
}
