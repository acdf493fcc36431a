// Procedural default environments (default_light.h).
#include "scene/default_light.h"

#include <algorithm>
#include <cmath>

#include "image/image.h"

namespace pxf {
namespace {

constexpr float kPi = 3.14159265358979f;
constexpr int kWidth = 512, kHeight = 256;  // 0.7 degree texels: the sun and softbox edges stay soft

// Environment's convention: u = 0.5 + atan2(d.x, -d.z) / (2 pi), v = acos(d.y) / pi.
glm::vec3 texel_direction(int x, int y) {
  float phi = ((x + 0.5f) / kWidth - 0.5f) * 2.0f * kPi;
  float theta = (y + 0.5f) / kHeight * kPi;
  return {std::sin(theta) * std::sin(phi), std::cos(theta), -std::sin(theta) * std::cos(phi)};
}

float smoothstep(float a, float b, float x) {
  float t = std::clamp((x - a) / (b - a), 0.0f, 1.0f);
  return t * t * (3.0f - 2.0f * t);
}

// A lobe around `axis` falling from 1 inside `inner` radians to 0 at `outer`.
float soft_disk(glm::vec3 d, glm::vec3 axis, float inner, float outer) {
  float angle = std::acos(std::clamp(glm::dot(d, glm::normalize(axis)), -1.0f, 1.0f));
  return 1.0f - smoothstep(inner, outer, angle);
}

// A rectangle-like softbox: a lobe with separate angular half-sizes along and across the horizon.
float softbox(glm::vec3 d, float azimuth, float elevation, float half_width, float half_height) {
  float d_az = std::atan2(d.x, -d.z) - azimuth;
  d_az = std::remainder(d_az, 2.0f * kPi);
  float d_el = std::asin(std::clamp(d.y, -1.0f, 1.0f)) - elevation;
  float edge = 0.04f;  // soft edge in radians
  return (1.0f - smoothstep(half_width - edge, half_width + edge, std::fabs(d_az))) *
         (1.0f - smoothstep(half_height - edge, half_height + edge, std::fabs(d_el)));
}

// The front of a glTF model faces +Z (the default camera looks along -Z from +Z), so "front
// left above" is (-1, 1.2, 1).
glm::vec3 sky_radiance(glm::vec3 d) {
  float above = smoothstep(-0.02f, 0.02f, d.y);  // no hard horizon line to alias
  float elevation = std::max(d.y, 0.0f);
  // Overcast sky (CIE overcast gradient (1 + 2 sin e) / 3), slightly cooler at the zenith.
  glm::vec3 horizon(1.0f, 0.98f, 0.95f), zenith(0.75f, 0.85f, 1.0f);
  glm::vec3 sky = glm::mix(horizon, zenith, elevation) * ((1.0f + 2.0f * elevation) / 3.0f) * 0.8f;
  glm::vec3 sun = glm::vec3(1.0f, 0.95f, 0.85f) * 80.0f * soft_disk(d, {-1.0f, 1.2f, 1.0f}, 0.05f, 0.12f);
  glm::vec3 ground(0.25f, 0.24f, 0.22f);
  return glm::mix(ground, sky + sun, above);
}

glm::vec3 studio_radiance(glm::vec3 d) {
  float above = smoothstep(-0.02f, 0.02f, d.y);
  glm::vec3 surround(0.12f);
  glm::vec3 key = glm::vec3(6.0f) * softbox(d, std::atan2(-1.0f, -1.0f), 0.6f, 0.35f, 0.3f);
  glm::vec3 fill = glm::vec3(1.5f) * softbox(d, std::atan2(1.2f, -0.8f), 0.3f, 0.4f, 0.35f);
  glm::vec3 rim = glm::vec3(3.0f) * softbox(d, 0.0f, 0.9f, 0.9f, 0.08f);
  glm::vec3 floor(0.05f);
  return glm::mix(floor, surround + key + fill + rim, above);
}

}  // namespace

const std::vector<std::string>& default_light_names() {
  static const std::vector<std::string> names = {"sky", "studio", "none"};
  return names;
}

DefaultLight parse_default_light(const std::string& name) {
  const std::vector<std::string>& names = default_light_names();
  for (size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return static_cast<DefaultLight>(i);
  throw Error("unknown default light '" + name + "' (sky, studio or none)");
}

const std::string& default_light_name(DefaultLight light) { return default_light_names().at(static_cast<size_t>(light)); }

bool scene_has_light(const Scene& scene) {
  if (!scene.lights.empty() || scene.environment) return true;
  for (const Mesh& mesh : scene.meshes) {
    const Material& m = scene.materials[mesh.material];
    if (m.is_emissive() && !m.emissive_texture.valid() && !mesh.triangles.empty()) return true;
  }
  return false;
}

Environment make_default_environment(DefaultLight light) {
  Environment env;
  env.source = "built-in " + default_light_name(light);
  Texture& tex = env.image;
  tex.name = env.source;
  tex.width = kWidth;
  tex.height = kHeight;
  tex.wrap_s = Wrap::Repeat;
  tex.wrap_t = Wrap::ClampToEdge;
  tex.texels.resize(static_cast<size_t>(kWidth) * kHeight);
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      glm::vec3 d = texel_direction(x, y);
      glm::vec3 c = light == DefaultLight::Studio ? studio_radiance(d) : sky_radiance(d);
      tex.texels[static_cast<size_t>(y) * kWidth + x] = glm::vec4(c, 1.0f);
    }
  return env;
}

std::string apply_default_light(Scene& scene, DefaultLight light) {
  if (scene_has_light(scene)) return "";
  if (light == DefaultLight::None)
    return "the scene has no lights and no environment (--default-light none): the image will be black";
  scene.environment = make_default_environment(light);
  return "the scene has no lights: lit by the built-in " + default_light_name(light) +
         " environment (--default-light sky|studio|none, or --env FILE)";
}

}  // namespace pxf
