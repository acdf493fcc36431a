// A Sponza-like courtyard, 20 m x 14 m: a tiled floor, two-storey arcades (piers + round arches)
// on both long sides with aisles behind them, brick walls, a fountain, iron balustrade grilles
// (alpha mask) and an open roof. Lit by a sun (KHR_lights_punctual) through the roof and a sky
// environment (environment.exr). The camera stands in the shaded aisle looking along the arcade,
// so most of what it sees is lit indirectly by the sunlit courtyard.
#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include "../gltf_builder.h"
#include "../procedural.h"
#include "../scenes.h"
#include "../sky.h"

namespace pxf::scenegen {
namespace {

constexpr float kHalfLength = 10.0f;   // courtyard spans x in [-10, 10]
constexpr float kArcadeZ = 4.0f;       // arcade center lines at z = +-4
constexpr float kBackWallZ = 7.0f;     // aisle back walls at z = +-7
constexpr float kBay = 2.5f;           // pier spacing
constexpr int kBays = 8;
constexpr float kFirstFloor = 5.0f;    // top of the ground arcade
constexpr float kSlab = 0.35f;
constexpr float kRoof = 9.0f;          // top of the upper arcade
const glm::vec3 kSunDirection = glm::normalize(glm::vec3(0.25f, -0.9f, -0.35f));  // travel direction

struct Storey {
  float base, springing, top, pier_width;
};
const Storey kGround{0.0f, 3.0f, kFirstFloor, 0.6f};
const Storey kUpper{kFirstFloor + kSlab, 7.4f, kRoof, 0.45f};

MeshData make_pier(const Storey& s) {
  const float h = 0.5f * s.pier_width;
  MeshData pier = make_box({-h, s.base, -h}, {h, s.top, h});
  // A plinth and a capital a little wider than the shaft.
  pier.append(make_box({-h - 0.08f, s.base, -h - 0.08f}, {h + 0.08f, s.base + 0.3f, h + 0.08f}));
  pier.append(make_box({-h - 0.06f, s.springing - 0.2f, -h - 0.06f}, {h + 0.06f, s.springing, h + 0.06f}));
  return pier;
}

MeshData make_arch(const Storey& s) {
  MeshData arch;
  const float half_span = 0.5f * (kBay - s.pier_width);
  arch.append(make_arch_wall(half_span, s.top - s.springing, s.pier_width, 48, 1.0f),
              glm::translate(glm::mat4(1.0f), {0.0f, s.springing, 0.0f}));
  return arch;
}

// Both aisles' floor slabs (first floor and roof) as world-space boxes.
MeshData make_slabs() {
  MeshData slabs;
  for (float side : {1.0f, -1.0f}) {
    const float inner = kArcadeZ - 0.5f * kGround.pier_width;
    for (float bottom : {kFirstFloor, kRoof}) {
      const glm::vec3 lo(-kHalfLength, bottom, side > 0 ? inner : -kBackWallZ);
      const glm::vec3 hi(kHalfLength, bottom + kSlab, side > 0 ? kBackWallZ : -inner);
      slabs.append(make_box(lo, hi));
    }
  }
  return slabs;
}

MeshData make_walls() {
  MeshData walls;
  const float height = kRoof + kSlab;
  const float end_height = 12.0f;
  const glm::vec3 x(1, 0, 0), y(0, 1, 0), z(0, 0, 1);
  const float length = 2.0f * kHalfLength, width = 2.0f * kBackWallZ;
  // Back walls face the courtyard; UVs in meters (the brick texture spans 1 m).
  walls.append(make_quad({kHalfLength, 0, kBackWallZ}, -length * x, height * y, {length, height}));
  walls.append(make_quad({-kHalfLength, 0, -kBackWallZ}, length * x, height * y, {length, height}));
  walls.append(make_quad({-kHalfLength, 0, kBackWallZ}, -width * z, end_height * y, {width, end_height}));
  walls.append(make_quad({kHalfLength, 0, -kBackWallZ}, width * z, end_height * y, {width, end_height}));
  return walls;
}

MeshData make_fountain() {
  // Basin: a lathed ring wall with a rim; a central column carrying a bowl.
  // Repeated profile points are creases (see make_lathe).
  const std::vector<glm::vec2> basin = {{1.3f, 0.0f}, {1.3f, 0.45f}, {1.3f, 0.45f}, {1.35f, 0.5f},
                                        {1.2f, 0.56f}, {1.1f, 0.5f}, {1.1f, 0.5f}, {1.1f, 0.15f},
                                        {1.1f, 0.15f}, {0.0f, 0.15f}};
  const std::vector<glm::vec2> bowl = {{0.0f, 1.1f}, {0.3f, 1.12f}, {0.55f, 1.25f}, {0.7f, 1.45f},
                                       {0.72f, 1.5f}, {0.65f, 1.5f}, {0.5f, 1.32f}, {0.0f, 1.28f}};
  MeshData fountain = make_lathe(basin, 64);
  fountain.append(make_cylinder({0, 0.15f, 0}, 0.14f, 0.97f, 32, false, false));
  fountain.append(make_lathe(bowl, 64));
  return fountain;
}

// Clear-sky radiance (linear RGB) for a direction, without the sun's disc (the sun is the
// punctual light); a circumsolar glow keeps the sun's direction visible in reflections.
glm::vec3 sky_radiance(const glm::vec3& d) {
  const glm::vec3 zenith(0.30f, 0.50f, 1.00f), horizon(0.85f, 0.92f, 1.05f), ground(0.22f, 0.2f, 0.18f);
  if (d.y < 0.0f) return glm::mix(horizon * 0.5f, ground, std::min(1.0f, -d.y * 6.0f));
  const float t = std::pow(1.0f - d.y, 3.0f);
  const float to_sun = std::acos(std::clamp(glm::dot(d, -kSunDirection), -1.0f, 1.0f));
  const float glow = 3.0f * std::exp(-to_sun * to_sun / 0.02f) + 0.3f * std::exp(-to_sun * to_sun / 0.3f);
  return glm::mix(zenith, horizon, t) + glm::vec3(1.0f, 0.9f, 0.7f) * glow;
}

}  // namespace

void write_atrium(const std::string& dir) {
  SceneBuilder scene("atrium");
  TileStyle floor_style;  // 4 x 4 tiles of 0.5 m per 2 m texture repeat
  const int floor = scene.add_material(add_texture_set(scene, paint_tiles(512, floor_style), "tiles", 0.02f, glm::vec2(0.5f)));
  const int brick = scene.add_material(add_texture_set(scene, paint_bricks(512, BrickStyle()), "brick", 0.008f));
  const int stone = scene.add_material(
      add_texture_set(scene, paint_stone(512, {0.62f, 0.53f, 0.41f}, 31), "stone", 0.01f));
  MaterialDesc grille = add_texture_set(scene, paint_grille(512, 8), "grille", 0.01f, glm::vec2(1.0f), 1.0f);
  grille.doubleSided = true;  // seen from both the courtyard and the gallery
  const int grille_material = scene.add_material(grille);

  scene.add_object("floor", make_quad({-kHalfLength, 0, kBackWallZ}, {2 * kHalfLength, 0, 0},
                                      {0, 0, -2 * kBackWallZ}, {2 * kHalfLength, 2 * kBackWallZ}),
                  floor);
  scene.add_object("walls", make_walls(), brick);
  scene.add_object("slabs", make_slabs(), stone);
  scene.add_object("fountain", make_fountain(), stone);

  const int ground_pier = scene.add_mesh("ground_pier", make_pier(kGround), stone);
  const int upper_pier = scene.add_mesh("upper_pier", make_pier(kUpper), stone);
  const int ground_arch = scene.add_mesh("ground_arch", make_arch(kGround), stone);
  const int upper_arch = scene.add_mesh("upper_arch", make_arch(kUpper), stone);
  const float grille_width = kBay - kUpper.pier_width;
  const int balustrade = scene.add_mesh(
      "balustrade", make_quad({-0.5f * grille_width, kUpper.base, 0}, {grille_width, 0, 0}, {0, 1, 0}, {grille_width, 1}),
      grille_material);
  for (float side : {1.0f, -1.0f}) {
    const std::string prefix = side > 0 ? "south_" : "north_";
    for (int k = 0; k <= kBays; ++k) {
      const float x = -kHalfLength + kBay * float(k);
      scene.add_node(prefix + "pier_" + std::to_string(k), ground_pier, {x, 0, side * kArcadeZ});
      scene.add_node(prefix + "upper_pier_" + std::to_string(k), upper_pier, {x, 0, side * kArcadeZ});
    }
    for (int k = 0; k < kBays; ++k) {
      const glm::vec3 center(-kHalfLength + kBay * (float(k) + 0.5f), 0, side * kArcadeZ);
      scene.add_node(prefix + "arch_" + std::to_string(k), ground_arch, center);
      scene.add_node(prefix + "upper_arch_" + std::to_string(k), upper_arch, center);
      scene.add_node(prefix + "balustrade_" + std::to_string(k), balustrade, center);
    }
  }

  scene.add_sun("sun", kSunDirection, {1.0f, 0.93f, 0.82f}, 10.0f);
  scene.set_camera({8.6f, 1.7f, 5.7f}, {-10.0f, 2.9f, 3.0f}, 1.0f, 16.0f / 9.0f);
  scene.set_render_defaults(false, 960, 540);
  scene.write(dir);
  write_environment(dir, paint_equirect(1024, 512, sky_radiance));
}

}  // namespace pxf::scenegen
