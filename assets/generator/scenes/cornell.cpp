// The Cornell box, 1 m on a side: red left wall, green right wall, white floor, ceiling and back
// wall, a perfect mirror sphere, a glass sphere and a single-sided area light under the ceiling.
// Box spans x in [-0.5, 0.5], y in [0, 1], z in [-0.5, 0.5]; its open side faces +Z, the camera.
#include "../gltf_builder.h"
#include "../scenes.h"

namespace pxf::scenegen {

void write_cornell(const std::string& dir) {
  SceneBuilder scene("cornell");
  // Reflectances of the measured Cornell box (linear RGB).
  const int white = scene.add_material(plain_material("white", {0.725f, 0.71f, 0.68f}));
  const int red = scene.add_material(plain_material("red", {0.63f, 0.065f, 0.05f}));
  const int green = scene.add_material(plain_material("green", {0.14f, 0.45f, 0.091f}));

  MaterialDesc mirror = plain_material("mirror", glm::vec3(0.95f), 0.0f);
  mirror.metallic = 1.0f;
  const int mirror_material = scene.add_material(mirror);

  MaterialDesc glass = plain_material("glass", glm::vec3(1.0f), 0.0f);
  glass.transmission = 1.0f;
  glass.ior = 1.5f;
  const int glass_material = scene.add_material(glass);

  // The warm light of the original box, radiance about (17, 12, 4): factor times strength.
  MaterialDesc light = plain_material("light", glm::vec3(0.78f));
  light.emissive = {1.0f, 0.706f, 0.235f};
  light.emissive_strength = 17.0f;
  const int light_material = scene.add_material(light);

  const glm::vec3 x(1, 0, 0), y(0, 1, 0), z(0, 0, 1);
  // Single-sided walls: cross(edge_u, edge_v) points into the box.
  scene.add_object("floor", make_quad({-0.5f, 0, 0.5f}, x, -z), white);
  scene.add_object("ceiling", make_quad({-0.5f, 1, -0.5f}, x, z), white);
  scene.add_object("back_wall", make_quad({-0.5f, 0, -0.5f}, x, y), white);
  scene.add_object("left_wall", make_quad({-0.5f, 0, 0.5f}, -z, y), red);
  scene.add_object("right_wall", make_quad({0.5f, 0, -0.5f}, z, y), green);
  scene.add_object("mirror_sphere", make_sphere({-0.22f, 0.2f, -0.2f}, 0.2f, 64, 32), mirror_material);
  scene.add_object("glass_sphere", make_sphere({0.23f, 0.18f, 0.17f}, 0.18f, 64, 32), glass_material);
  // 0.25 m x 0.2 m, 2 mm under the ceiling; cross(x, z) = -y, so it emits downwards only.
  scene.add_object("light", make_quad({-0.125f, 0.998f, -0.1f}, 0.25f * x, 0.2f * z), light_material);

  // Looking down -Z through the open side; yfov 0.69 rad frames the 1 m opening from 1.39 m.
  scene.set_camera({0.0f, 0.5f, 1.9f}, {0.0f, 0.5f, 0.0f}, 0.69f, 1.0f);
  scene.set_render_defaults(false, 512, 512);
  scene.write(dir);
}

}  // namespace pxf::scenegen
