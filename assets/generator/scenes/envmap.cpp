// Two detailed objects in a photo studio lit only by an HDR environment (environment.exr, three
// softboxes and a strip light over a dark backdrop): a torus knot with spiral ridges and a
// fish-scale glaze (base color, roughness and normal textures), and a perfect mirror sphere, on a
// ground disc. Renders with the usual LV/HV split: all-HV (`--all-hv`) filters the direct light on
// the knot's texture too and measured worse at equal time (docs/measurements.md, "Environment-lit
// scenes").
#include <glm/gtc/constants.hpp>

#include "../gltf_builder.h"
#include "../procedural.h"
#include "../scenes.h"
#include "../sky.h"

namespace pxf::scenegen {
namespace {

// A (2, 3) torus knot of overall radius about 0.75 m in the XY plane, centered at `center`.
glm::vec3 torus_knot(float t, const glm::vec3& center) {
  constexpr float p = 2.0f, q = 3.0f, radius = 0.5f;
  const float u = t * p * glm::two_pi<float>();
  const float cs = std::cos(q / p * u);
  return center + radius * glm::vec3((2.0f + cs) * 0.5f * std::cos(u), (2.0f + cs) * 0.5f * std::sin(u),
                                     std::sin(q / p * u) * 0.5f);
}

MeshData make_ridged_knot(const glm::vec3& center) {
  // Twisted-rope ridges: three helical ridges winding 48 times along the knot.
  auto ridges = [](float t, float phi) {
    const float s = std::sin(3.0f * phi + 48.0f * glm::two_pi<float>() * t);
    return 0.012f * s * s * s;
  };
  return make_swept_tube([&](float t) { return torus_knot(t, center); }, 0.15f, 384, 40, {24.0f, 3.0f}, ridges);
}

struct Softbox {
  glm::vec3 direction;   // center of the box as seen from the origin
  glm::vec2 half_size;    // half extents, tangent of the angle
  glm::vec3 radiance;
};

// A photo studio: dark gradient backdrop, dim floor, and bright rectangular light sources.
glm::vec3 studio_radiance(const glm::vec3& d) {
  static const Softbox boxes[] = {
      {glm::normalize(glm::vec3(-1.0f, 0.8f, 1.0f)), {0.45f, 0.32f}, {60.0f, 55.0f, 48.0f}},   // key, front left
      {glm::normalize(glm::vec3(1.2f, 0.4f, 0.8f)), {0.3f, 0.4f}, {9.0f, 10.0f, 12.0f}},       // fill, right
      {glm::normalize(glm::vec3(0.2f, 1.0f, -0.2f)), {0.8f, 0.08f}, {35.0f, 35.0f, 35.0f}},    // strip overhead
      {glm::normalize(glm::vec3(0.6f, 0.5f, -1.0f)), {0.15f, 0.35f}, {80.0f, 70.0f, 60.0f}},   // rim, behind
  };
  const float elevation = d.y;
  glm::vec3 radiance = elevation >= 0.0f ? glm::mix(glm::vec3(0.09f, 0.09f, 0.1f), glm::vec3(0.02f), elevation)
                                         : glm::vec3(0.05f, 0.045f, 0.04f);
  for (const Softbox& box : boxes) {
    const float facing = glm::dot(d, box.direction);
    if (facing <= 0.0f) continue;
    const glm::vec3 right = glm::normalize(glm::cross(box.direction, glm::vec3(0, 1, 0) + glm::vec3(0, 0, 1e-3f)));
    const glm::vec3 up = glm::cross(right, box.direction);
    const glm::vec2 local(std::abs(glm::dot(d, right)) / facing, std::abs(glm::dot(d, up)) / facing);
    // Soft-edged rectangle with a slightly brighter center, like a diffusion panel.
    const glm::vec2 edge = glm::clamp((box.half_size - local) / (0.04f * box.half_size + 0.005f), 0.0f, 1.0f);
    const float falloff = 1.0f - 0.3f * glm::length(local / box.half_size) * 0.5f;
    radiance += box.radiance * edge.x * edge.y * falloff;
  }
  return radiance;
}

}  // namespace

void write_envmap(const std::string& dir) {
  SceneBuilder scene("envmap");
  const int scales = scene.add_material(add_texture_set(scene, paint_scales(512, 8, 71), "scales", 0.015f));
  MaterialDesc mirror = plain_material("mirror", glm::vec3(0.95f), 0.0f);
  mirror.metallic = 1.0f;
  const int mirror_material = scene.add_material(mirror);
  const int ground = scene.add_material(plain_material("studio_floor", {0.3f, 0.3f, 0.3f}, 0.85f));

  scene.add_object("ground", make_disc({0, 0, 0}, 4.0f, 128), ground);
  scene.add_object("scaled_knot", make_ridged_knot({-0.55f, 0.93f, 0.0f}), scales);
  scene.add_object("mirror_sphere", make_sphere({0.95f, 0.5f, 0.35f}, 0.5f, 96, 48), mirror_material);

  scene.set_camera({0.2f, 1.35f, 3.9f}, {0.15f, 0.7f, 0.0f}, 0.7f, 16.0f / 9.0f);
  scene.set_render_defaults(false, 960, 540);
  scene.write(dir);
  write_environment(dir, paint_equirect(2048, 1024, studio_radiance));
}

}  // namespace pxf::scenegen
