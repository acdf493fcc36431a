// The Cornell box, 1 m on a side: red left wall, green right wall, white floor, ceiling and back
// wall, a perfect mirror sphere, a glass sphere and a single-sided area light under the ceiling.
// Box spans x in [-0.5, 0.5], y in [0, 1], z in [-0.5, 0.5]; its open side faces +Z, the camera.
#include "../gltf_builder.h"
#include "../scenes.h"

namespace pxf::scenegen {

bool writeCornell(const std::string& dir, std::string* error) {
  SceneBuilder scene("cornell");
  // Reflectances of the measured Cornell box (linear RGB).
  const int white = scene.addMaterial(plainMaterial("white", {0.725f, 0.71f, 0.68f}));
  const int red = scene.addMaterial(plainMaterial("red", {0.63f, 0.065f, 0.05f}));
  const int green = scene.addMaterial(plainMaterial("green", {0.14f, 0.45f, 0.091f}));

  MaterialDesc mirror = plainMaterial("mirror", glm::vec3(0.95f), 0.0f);
  mirror.metallic = 1.0f;
  const int mirrorMaterial = scene.addMaterial(mirror);

  MaterialDesc glass = plainMaterial("glass", glm::vec3(1.0f), 0.0f);
  glass.transmission = 1.0f;
  glass.ior = 1.5f;
  const int glassMaterial = scene.addMaterial(glass);

  // The warm light of the original box, radiance about (17, 12, 4): factor times strength.
  MaterialDesc light = plainMaterial("light", glm::vec3(0.78f));
  light.emissive = {1.0f, 0.706f, 0.235f};
  light.emissiveStrength = 17.0f;
  const int lightMaterial = scene.addMaterial(light);

  const glm::vec3 x(1, 0, 0), y(0, 1, 0), z(0, 0, 1);
  // Single-sided walls: cross(edgeU, edgeV) points into the box.
  scene.addObject("floor", makeQuad({-0.5f, 0, 0.5f}, x, -z), white);
  scene.addObject("ceiling", makeQuad({-0.5f, 1, -0.5f}, x, z), white);
  scene.addObject("back_wall", makeQuad({-0.5f, 0, -0.5f}, x, y), white);
  scene.addObject("left_wall", makeQuad({-0.5f, 0, 0.5f}, -z, y), red);
  scene.addObject("right_wall", makeQuad({0.5f, 0, -0.5f}, z, y), green);
  scene.addObject("mirror_sphere", makeSphere({-0.22f, 0.2f, -0.2f}, 0.2f, 64, 32), mirrorMaterial);
  scene.addObject("glass_sphere", makeSphere({0.23f, 0.18f, 0.17f}, 0.18f, 64, 32), glassMaterial);
  // 0.25 m x 0.2 m, 2 mm under the ceiling; cross(x, z) = -y, so it emits downwards only.
  scene.addObject("light", makeQuad({-0.125f, 0.998f, -0.1f}, 0.25f * x, 0.2f * z), lightMaterial);

  // Looking down -Z through the open side; yfov 0.69 rad frames the 1 m opening from 1.39 m.
  scene.setCamera({0.0f, 0.5f, 1.9f}, {0.0f, 0.5f, 0.0f}, 0.69f, 1.0f);
  scene.setRenderDefaults(false, 512, 512);
  return scene.write(dir, error);
}

}  // namespace pxf::scenegen
