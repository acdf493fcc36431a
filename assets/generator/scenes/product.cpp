// A product shot: a sci-fi helmet floating in a daylight environment, its only light
// (environment.exr: a cloudy sky with the sun as a small, very bright disc, so direct light is
// noisy through every glossy lobe). It stands for the most common public glTF file, a textured,
// normal-mapped PBR asset under an HDR sky, shown as viewers show it: nearly all of its
// light is direct light at the first surface, so with no ground under it, it has almost no
// indirect light. Several materials, each with fine texture and normal detail: a clear-coated
// painted shell with panel seams, rivets, stencils, grime and chipped paint (metallic where
// chipped), brushed metal trim with a roughness map and scratches, a gold visor with smudges and
// fingerprints.
#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "../gltf_builder.h"
#include "../procedural.h"
#include "../scenes.h"
#include "../sky.h"

namespace pxf::scenegen {
namespace {

// The helmet is built around the centre of its shell (an ellipsoid) and facing +Z.
const glm::vec3 kShell(0.155f, 0.165f, 0.155f);  // semi-axes, meters
constexpr float kShellRim = 1.95f;                 // polar angle of the open lower rim
const glm::vec3 kSunDirection = glm::normalize(glm::vec3(0.45f, -0.8f, -0.4f));  // travel direction

// The visor's outline: a superellipse in (azimuth, elevation) around the helmet's front.
constexpr float kVisorAzimuth = 0.95f, kVisorElevation = 0.36f, kVisorCentre = -0.03f;

glm::vec2 visor_outline(float t) {  // t in [0, 1) around the outline -> (azimuth, elevation)
  const float psi = t * glm::two_pi<float>(), exponent = 2.0f / 5.0f;
  const float c = std::cos(psi), s = std::sin(psi);
  return {kVisorAzimuth * std::copysign(std::pow(std::abs(c), exponent), c),
          kVisorCentre + kVisorElevation * std::copysign(std::pow(std::abs(s), exponent), s)};
}

// A direction from azimuth (0 = +Z, towards +X) and elevation.
glm::vec3 direction(float azimuth, float elevation) {
  return {std::cos(elevation) * std::sin(azimuth), std::sin(elevation), std::cos(elevation) * std::cos(azimuth)};
}

// The shell: painted panels tiled 4 times around and twice from the crown to the rim.
MeshData make_shell() {
  return make_surface(128, 60, [](float u, float v) {
    const float phi = u * glm::two_pi<float>(), theta = v * kShellRim;  // phi = 0 at the back
    const glm::vec3 d(std::sin(theta) * std::sin(phi), std::cos(theta), -std::sin(theta) * std::cos(phi));
    return SurfacePoint{kShell * d, d / kShell, {u * 4.0f, v * 2.0f}};
  });
}

// The visor: a bulge 3 % above the shell inside the outline (a fan from its centre).
MeshData make_visor() {
  const glm::vec3 axes = kShell * 1.03f;
  return make_surface(128, 20, [&](float u, float v) {
    const glm::vec2 edge = visor_outline(u);
    const float azimuth = v * edge.x, elevation = kVisorCentre + v * (edge.y - kVisorCentre);
    const glm::vec3 d = direction(azimuth, elevation);
    return SurfacePoint{axes * d, d / axes,
                        {0.5f + 0.5f * azimuth / kVisorAzimuth, 0.5f - 0.5f * (elevation - kVisorCentre) / kVisorElevation}};
  });
}

// A rounded trim around the visor, on the step between shell and visor.
MeshData make_visor_trim() {
  const glm::vec3 axes = kShell * 1.018f;
  return make_swept_tube([&](float t) {
    const glm::vec2 edge = visor_outline(t);
    return axes * direction(edge.x, edge.y);
  }, 0.0075f, 256, 10, {24.0f, 1.0f});
}

// Lathe UVs run 2 * pi * 0.1 m * uv_per_meter around; this makes that 2 (the texture tiles).
constexpr float kLatheUv = 10.0f / glm::pi<float>();

MeshData make_neck_ring() {
  // Repeated points are creases.
  const std::vector<glm::vec2> profile = {
      {0.12f, -0.06f},   {0.12f, -0.125f},  {0.12f, -0.125f},  {0.148f, -0.125f}, {0.148f, -0.125f},
      {0.156f, -0.117f}, {0.159f, -0.096f}, {0.159f, -0.096f}, {0.151f, -0.09f},  {0.151f, -0.075f},
      {0.151f, -0.075f}, {0.158f, -0.07f},  {0.158f, -0.056f}, {0.158f, -0.056f}, {0.138f, -0.048f}};
  return make_lathe(profile, 128, kLatheUv);
}

MeshData make_crown_vent() {
  // Concentric vent rings on the crown, covering the shell's pole.
  std::vector<glm::vec2> profile = {{0.05f, 0.148f}, {0.047f, 0.16f}, {0.047f, 0.16f}};
  for (int ring = 0; ring < 4; ++ring) {
    const float r = 0.042f - 0.009f * float(ring), y = 0.163f + 0.0025f * float(ring);
    profile.insert(profile.end(), {{r, y}, {r, y + 0.003f}, {r, y + 0.003f}, {r - 0.004f, y + 0.003f},
                                   {r - 0.004f, y + 0.003f}, {r - 0.004f, y + 0.0015f}});
  }
  profile.push_back({0.0f, 0.1735f});
  return make_lathe(profile, 96, kLatheUv);
}

// An ear pod on the +X side (built along +Y, then turned onto +X or -X).
MeshData make_ear_pod(bool left) {
  const std::vector<glm::vec2> profile = {{0.052f, 0.125f}, {0.05f, 0.158f}, {0.05f, 0.158f}, {0.046f, 0.171f},
                                          {0.041f, 0.177f}, {0.041f, 0.177f}, {0.036f, 0.177f}, {0.036f, 0.177f},
                                          {0.034f, 0.182f}, {0.028f, 0.185f}, {0.0f, 0.1855f}};
  MeshData pod;
  const glm::mat4 turn = glm::rotate(glm::mat4(1.0f), left ? glm::half_pi<float>() : -glm::half_pi<float>(), {0, 0, 1});
  pod.append(make_lathe(profile, 96, kLatheUv), turn);
  return pod;
}

MeshData make_antenna() {
  MeshData antenna;
  const glm::mat4 base = glm::rotate(glm::translate(glm::mat4(1.0f), {0.172f, 0.02f, -0.02f}), -0.45f, {1, 0, 0});
  antenna.append(make_cylinder({0, 0, 0}, 0.0025f, 0.17f, 16), base);
  antenna.append(make_cylinder({0, 0, 0}, 0.006f, 0.012f, 24), base);
  return antenna;
}

}  // namespace

void write_product(const std::string& dir) {
  SceneBuilder scene("product");
  MaterialDesc paint = add_texture_set(scene, paint_hull_panels(512, {0.13f, 0.25f, 0.4f}, {0.85f, 0.28f, 0.04f}, 81),
                                       "hull_paint", 0.004f);
  paint.clearcoat = 1.0f;  // lacquer over the paint (and over the chips)
  paint.clearcoat_roughness = 0.06f;
  const int hull = scene.add_material(paint);
  const int metal = scene.add_material(
      add_texture_set(scene, paint_brushed_metal(512, {0.8f, 0.79f, 0.77f}, 83), "brushed_metal", 0.002f, glm::vec2(1.0f), 1.0f));
  const int visor = scene.add_material(
      add_texture_set(scene, paint_smudged(256, {1.0f, 0.76f, 0.33f}, 85), "visor", 0.002f, glm::vec2(1.0f), 1.0f));
  const int tip = scene.add_material(plain_material("antenna_tip", {0.6f, 0.03f, 0.02f}, 0.25f));

  MeshData trim = make_visor_trim();
  trim.append(make_neck_ring());
  trim.append(make_crown_vent());
  trim.append(make_ear_pod(false));
  trim.append(make_ear_pod(true));
  trim.append(make_antenna());
  MeshData antenna_tip;
  const glm::mat4 base = glm::rotate(glm::translate(glm::mat4(1.0f), {0.172f, 0.02f, -0.02f}), -0.45f, {1, 0, 0});
  antenna_tip.append(make_sphere({0.0f, 0.17f, 0.0f}, 0.007f, 24, 12), base);

  scene.add_object("helmet_shell", make_shell(), hull);
  scene.add_object("helmet_visor", make_visor(), visor);
  scene.add_object("helmet_trim", trim, metal);
  scene.add_object("antenna_tip", antenna_tip, tip);

  scene.set_camera({0.55f, -0.03f, 0.78f}, {0.0f, 0.035f, 0.0f}, 0.5f, 16.0f / 9.0f);
  scene.set_render_defaults(false, 960, 540);
  scene.write(dir);
  DaylightSky sky;
  sky.sun_direction = kSunDirection;
  sky.sun_radius = 0.045f;  // a hazy sun: wider and dimmer than the real one, the same irradiance
  sky.sun_radiance = {5600.0f, 5300.0f, 4700.0f};
  sky.clouds = 0.45f;
  sky.seed = 87;
  write_environment(dir, paint_equirect(1024, 512, [&](const glm::vec3& d) { return daylight_radiance(sky, d); }));
}

}  // namespace pxf::scenegen
