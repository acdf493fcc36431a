// A furnished living room, 5 m x 5 m x 3 m, closed on every side but for one 1.6 m x 1.4 m window,
// and lit only by a daylight environment (environment.exr: a clear sky with the sun as a small,
// very bright disc) through that window: no lights inside. Sunlight lands on a patch of floor and
// rug, and that patch lights the rest of the room. It stands for the most common interior:
// next-event estimation towards the sky is blocked by the walls almost everywhere, and
// BSDF sampling rarely leaves through the window. Textured diffuse surfaces (oak floor, plaster,
// rug, upholstery) and some glossy ones (lacquered table, ceramics, metal lamp, picture glaze).
#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <tuple>

#include "../gltf_builder.h"
#include "../procedural.h"
#include "../scenes.h"
#include "../sky.h"

namespace pxf::scenegen {
namespace {

// Room interior: x, z in [-2.5, 2.5], y in [0, 3]; walls, floor and ceiling 0.2 m thick.
constexpr float kRoom = 2.5f, kHeight = 3.0f, kWall = 0.2f;
// The window, in the left wall (x = -2.5): 1.6 m wide around z = kWindowZ, from sill to head.
constexpr float kWindowZ = 0.2f, kWindowHalfWidth = 0.8f, kSill = 0.85f, kHead = 2.25f;
// Afternoon sun, 34 degrees high, shining in through the window and towards the back.
const glm::vec3 kSunDirection = glm::normalize(glm::vec3(0.75f, -0.55f, -0.33f));  // travel direction

struct Materials {
  int floor, plaster, ceiling, frame, oak, walnut, sofa, cushion, curtain, linen, rug, metal, white_ceramic;
  int teal_ceramic, chair_paint, leaves, pot, canvas_a, canvas_b, canvas_c, picture_frame;
  int books[4];
};

Materials add_materials(SceneBuilder& scene) {
  Materials m{};
  MaterialDesc oak = add_texture_set(scene, paint_wood(512, 6, {0.6f, 0.42f, 0.25f}, {0.36f, 0.22f, 0.11f}, 91),
                                     "oak", 0.004f, glm::vec2(1.2f));
  oak.name = "oak_floor";
  m.floor = scene.add_material(oak);
  oak.name = "oak";
  oak.roughness = 0.7f;  // scales the texture's roughness: oiled furniture is glossier than the floor
  m.oak = scene.add_material(oak);
  oak.name = "walnut";
  oak.base_color = {0.55f, 0.45f, 0.4f, 1.0f};
  oak.roughness = 0.45f;
  oak.clearcoat = 1.0f;  // a lacquered table top
  oak.clearcoat_roughness = 0.05f;
  m.walnut = scene.add_material(oak);

  MaterialDesc plaster = add_texture_set(scene, paint_plaster(256, {0.78f, 0.76f, 0.72f}, 93), "plaster", 0.01f,
                                         glm::vec2(0.5f));
  m.plaster = scene.add_material(plaster);
  m.ceiling = scene.add_material(plain_material("ceiling_paint", {0.82f, 0.82f, 0.8f}, 0.9f));
  m.frame = scene.add_material(plain_material("window_frame", {0.85f, 0.85f, 0.83f}, 0.3f));

  MaterialDesc fabric = add_texture_set(scene, paint_fabric(256, 48, 95), "fabric", 0.003f, glm::vec2(4.0f));
  fabric.name = "sofa_fabric";
  fabric.base_color = {0.3f, 0.4f, 0.5f, 1.0f};
  m.sofa = scene.add_material(fabric);
  fabric.name = "cushion_fabric";
  fabric.base_color = {0.85f, 0.55f, 0.12f, 1.0f};
  m.cushion = scene.add_material(fabric);
  fabric.doubleSided = true;  // curtains and the lamp shade are single sheets
  fabric.name = "curtain_fabric";
  fabric.base_color = {0.42f, 0.5f, 0.38f, 1.0f};
  m.curtain = scene.add_material(fabric);
  fabric.name = "linen";
  fabric.base_color = {0.95f, 0.9f, 0.8f, 1.0f};
  m.linen = scene.add_material(fabric);
  m.rug = scene.add_material(add_texture_set(scene, paint_rug(512, 97), "rug", 0.002f));

  MaterialDesc metal = plain_material("brass", {0.85f, 0.68f, 0.4f}, 0.25f);
  metal.metallic = 1.0f;
  m.metal = scene.add_material(metal);
  m.white_ceramic = scene.add_material(plain_material("white_ceramic", {0.85f, 0.84f, 0.8f}, 0.1f));
  m.teal_ceramic = scene.add_material(plain_material("teal_ceramic", {0.05f, 0.3f, 0.32f}, 0.15f));
  m.chair_paint = scene.add_material(plain_material("chair_paint", {0.08f, 0.16f, 0.12f}, 0.35f));
  m.leaves = scene.add_material(plain_material("leaves", {0.1f, 0.3f, 0.06f}, 0.5f));
  m.pot = scene.add_material(plain_material("terracotta", {0.55f, 0.25f, 0.14f}, 0.8f));
  m.canvas_a = scene.add_material(plain_material("canvas_ochre", {0.75f, 0.5f, 0.15f}, 0.4f));
  m.canvas_b = scene.add_material(plain_material("canvas_blue", {0.1f, 0.2f, 0.45f}, 0.4f));
  m.canvas_c = scene.add_material(plain_material("canvas_cream", {0.8f, 0.75f, 0.65f}, 0.4f));
  m.picture_frame = scene.add_material(plain_material("black_lacquer", glm::vec3(0.03f), 0.15f));
  const glm::vec3 book_colors[4] = {{0.5f, 0.08f, 0.06f}, {0.08f, 0.2f, 0.35f}, {0.7f, 0.62f, 0.45f}, {0.12f, 0.3f, 0.12f}};
  for (int i = 0; i < 4; ++i)
    m.books[i] = scene.add_material(plain_material("book_" + std::to_string(i), book_colors[i], 0.6f));
  return m;
}

// Walls, floor and ceiling as closed boxes; the left wall is four boxes around the window opening.
void add_shell(SceneBuilder& scene, const Materials& m) {
  const float outer = kRoom + kWall;
  MeshData walls;
  const float z0 = kWindowZ - kWindowHalfWidth, z1 = kWindowZ + kWindowHalfWidth;
  walls.append(make_box({-outer, 0, -outer}, {-kRoom, kSill, outer}, 0.5f));         // under the window
  walls.append(make_box({-outer, kHead, -outer}, {-kRoom, kHeight, outer}, 0.5f));   // over it
  walls.append(make_box({-outer, kSill, -outer}, {-kRoom, kHead, z0}, 0.5f));        // beside it
  walls.append(make_box({-outer, kSill, z1}, {-kRoom, kHead, outer}, 0.5f));
  walls.append(make_box({kRoom, 0, -outer}, {outer, kHeight, outer}, 0.5f));          // right
  walls.append(make_box({-kRoom, 0, -outer}, {kRoom, kHeight, -kRoom}, 0.5f));        // back
  walls.append(make_box({-kRoom, 0, kRoom}, {kRoom, kHeight, outer}, 0.5f));          // front
  scene.add_object("walls", walls, m.plaster);
  scene.add_object("floor", make_box({-outer, -kWall, -outer}, {outer, 0, outer}), m.floor);
  scene.add_object("ceiling", make_box({-outer, kHeight, -outer}, {outer, kHeight + kWall, outer}), m.ceiling);

  // Window frame in the middle of the wall's depth: jambs, head, sill, a mullion and a transom.
  MeshData frame;
  const float x0 = -kRoom - 0.14f, x1 = -kRoom - 0.06f, f = 0.05f;
  frame.append(make_box({x0, kSill, z0}, {x1, kHead, z0 + f}));
  frame.append(make_box({x0, kSill, z1 - f}, {x1, kHead, z1}));
  frame.append(make_box({x0, kHead - f, z0}, {x1, kHead, z1}));
  frame.append(make_box({x0, kSill, z0}, {x1, kSill + f, z1}));
  frame.append(make_box({x0, kSill, kWindowZ - 0.025f}, {x1, kHead, kWindowZ + 0.025f}));
  frame.append(make_box({x0, 1.8f, z0}, {x1, 1.84f, z1}));
  scene.add_object("window_frame", frame, m.frame);
  scene.add_object("window_sill", make_box({-kRoom - 0.06f, kSill - 0.03f, z0 - 0.08f}, {-kRoom + 0.12f, kSill, z1 + 0.08f}), m.oak);
  // Pleated curtains drawn to either side of the window, on a rod above it.
  MeshData curtains;
  constexpr float kCurtainWidth = 0.5f, kCurtainTop = 2.6f, kCurtainBottom = 0.04f;
  for (float z_start : {z0 - 0.6f, z1 + 0.1f}) {
    curtains.append(make_surface(96, 1, [&](float u, float v) {
      const float pleat = glm::two_pi<float>() * 7.0f * u;
      const float x = -kRoom + 0.08f + 0.03f * std::sin(pleat), dx_du = 0.03f * 7.0f * glm::two_pi<float>() * std::cos(pleat);
      return SurfacePoint{{x, kCurtainTop - v * (kCurtainTop - kCurtainBottom), z_start + u * kCurtainWidth},
                          {kCurtainWidth, 0.0f, -dx_du}, {u * kCurtainWidth, v * (kCurtainTop - kCurtainBottom)}};
    }));
  }
  curtains.append(make_cylinder({0, 0, 0}, 0.015f, 2.9f, 16),
                  glm::rotate(glm::translate(glm::mat4(1.0f), {-kRoom + 0.08f, 2.62f, z1 + 0.65f}), -glm::half_pi<float>(), {1, 0, 0}));
  scene.add_object("curtains", curtains, m.curtain);
}

void add_sofa(SceneBuilder& scene, const Materials& m) {
  const float x0 = -0.3f, x1 = 1.9f, back = -kRoom, front = -kRoom + 0.9f;
  MeshData body, cushions, legs;
  body.append(make_box({x0, 0.1f, back}, {x1, 0.42f, front}, 1.0f));                   // base
  body.append(make_box({x0, 0.42f, back}, {x1, 0.88f, back + 0.22f}, 1.0f));          // back rest
  body.append(make_box({x0, 0.42f, back + 0.22f}, {x0 + 0.18f, 0.64f, front}, 1.0f));  // arms
  body.append(make_box({x1 - 0.18f, 0.42f, back + 0.22f}, {x1, 0.64f, front}, 1.0f));
  const float seat = (x1 - x0 - 0.36f) / 2.0f;
  for (int i = 0; i < 2; ++i) {
    const float a = x0 + 0.18f + seat * float(i) + 0.01f;
    body.append(make_box({a, 0.42f, back + 0.24f}, {a + seat - 0.02f, 0.55f, front - 0.01f}, 1.0f));
  }
  cushions.append(make_box({x0 + 0.25f, 0.55f, back + 0.22f}, {x0 + 0.7f, 0.95f, back + 0.36f}, 1.0f));
  cushions.append(make_box({x1 - 0.7f, 0.55f, back + 0.22f}, {x1 - 0.25f, 0.92f, back + 0.36f}, 1.0f));
  for (float x : {x0 + 0.08f, x1 - 0.08f})
    for (float z : {back + 0.08f, front - 0.08f}) legs.append(make_cylinder({x, 0, z}, 0.025f, 0.1f, 16));
  scene.add_object("sofa", body, m.sofa);
  scene.add_object("cushions", cushions, m.cushion);
  scene.add_object("sofa_legs", legs, m.metal);
}

void add_rug_and_tables(SceneBuilder& scene, const Materials& m) {
  // Rug: a 1 cm slab with the pattern on a quad just above it.
  const float rx0 = -0.35f, rx1 = 2.05f, rz0 = -1.5f, rz1 = 0.3f;
  MeshData rug = make_box({rx0, 0.0f, rz0}, {rx1, 0.01f, rz1}, 1.0f);
  rug.append(make_quad({rx0, 0.011f, rz1}, {rx1 - rx0, 0, 0}, {0, 0, rz0 - rz1}));
  scene.add_object("rug", rug, m.rug);

  // A lacquered walnut coffee table on brass legs in front of the sofa.
  MeshData legs;
  scene.add_object("coffee_table", make_box({0.15f, 0.38f, -1.2f}, {1.35f, 0.42f, -0.6f}, 1.0f), m.walnut);
  for (float x : {0.2f, 1.3f})
    for (float z : {-1.15f, -0.65f}) legs.append(make_cylinder({x, 0.011f, z}, 0.018f, 0.369f, 16));

  // Dining table and two chairs, oak and painted, near the front.
  const float tx0 = -1.9f, tx1 = -0.8f, tz0 = 0.9f, tz1 = 1.8f;
  MeshData table = make_box({tx0, 0.72f, tz0}, {tx1, 0.76f, tz1}, 1.0f);
  for (float x : {tx0 + 0.06f, tx1 - 0.1f})
    for (float z : {tz0 + 0.06f, tz1 - 0.1f}) table.append(make_box({x, 0.0f, z}, {x + 0.04f, 0.72f, z + 0.04f}, 1.0f));
  scene.add_object("dining_table", table, m.oak);
  MeshData chairs;
  for (const auto& [cx, cz, facing] : {std::tuple{-1.35f, 0.6f, 1.0f}, std::tuple{-1.35f, 2.1f, -1.0f}}) {
    MeshData chair;
    chair.append(make_box({-0.22f, 0.43f, -0.22f}, {0.22f, 0.47f, 0.22f}));  // seat
    for (float x : {-0.2f, 0.17f})
      for (float z : {-0.2f, 0.17f}) chair.append(make_box({x, 0.0f, z}, {x + 0.03f, 0.43f, z + 0.03f}));
    for (float x : {-0.2f, 0.17f}) chair.append(make_box({x, 0.47f, -0.22f}, {x + 0.03f, 0.95f, -0.19f}));  // back posts
    for (float y : {0.62f, 0.86f}) chair.append(make_box({-0.2f, y, -0.22f}, {0.2f, y + 0.06f, -0.19f}));  // back rails
    // facing +1: the seat's back towards -z, the sitter faces the table at +z.
    glm::mat4 place = glm::translate(glm::mat4(1.0f), {cx, 0.0f, cz});
    if (facing < 0.0f) place = glm::rotate(place, glm::pi<float>(), {0, 1, 0});
    chairs.append(chair, place);
  }
  scene.add_object("chairs", chairs, m.chair_paint);
  MeshData bowl;
  bowl.append(make_lathe({{0.0f, 0.0f}, {0.05f, 0.0f}, {0.05f, 0.0f}, {0.13f, 0.06f}, {0.15f, 0.1f}, {0.14f, 0.1f},
                          {0.11f, 0.05f}, {0.0f, 0.03f}}, 48),
              glm::translate(glm::mat4(1.0f), {-1.35f, 0.76f, 1.35f}));
  scene.add_object("fruit_bowl", bowl, m.white_ceramic);
  // Vase and a stack of books on the coffee table.
  MeshData vase;
  vase.append(make_lathe({{0.0f, 0.0f}, {0.05f, 0.0f}, {0.05f, 0.0f}, {0.08f, 0.08f}, {0.07f, 0.2f}, {0.035f, 0.27f},
                          {0.04f, 0.3f}, {0.04f, 0.3f}, {0.0f, 0.3f}}, 48),
              glm::translate(glm::mat4(1.0f), {1.05f, 0.42f, -0.9f}));
  scene.add_object("vase", vase, m.teal_ceramic);
  scene.add_object("table_books", make_box({0.35f, 0.42f, -1.05f}, {0.65f, 0.47f, -0.82f}), m.books[0]);
  scene.add_object("coffee_table_legs", legs, m.metal);
}

// A bookshelf against the back wall, left of the sofa, and a plant and a floor lamp.
void add_shelf_and_decor(SceneBuilder& scene, const Materials& m) {
  const float x0 = -2.3f, x1 = -1.0f, back = -kRoom, front = -kRoom + 0.35f, top = 1.9f;
  MeshData shelf;
  shelf.append(make_box({x0, 0.0f, back}, {x0 + 0.03f, top, front}, 1.0f));
  shelf.append(make_box({x1 - 0.03f, 0.0f, back}, {x1, top, front}, 1.0f));
  const float levels[] = {0.05f, 0.5f, 0.95f, 1.4f, top - 0.03f};
  for (float y : levels) shelf.append(make_box({x0 + 0.03f, y, back}, {x1 - 0.03f, y + 0.03f, front}, 1.0f));
  scene.add_object("bookshelf", shelf, m.oak);
  MeshData books[4];
  for (int level = 0; level < 4; ++level) {
    float x = x0 + 0.05f + 0.1f * hash01(uint32_t(level), 0, 7);
    const float y = levels[level] + 0.03f;
    for (int k = 0; x < x1 - 0.12f; ++k) {
      const float width = 0.025f + 0.03f * hash01(uint32_t(level), uint32_t(k), 11);
      const float height = 0.22f + 0.15f * hash01(uint32_t(level), uint32_t(k), 13);
      const float depth = 0.2f + 0.08f * hash01(uint32_t(level), uint32_t(k), 17);
      const int color = int(hash01(uint32_t(level), uint32_t(k), 19) * 4.0f) % 4;
      if (hash01(uint32_t(level), uint32_t(k), 23) < 0.12f) {
        x += 0.12f;  // a gap
        continue;
      }
      books[color].append(make_box({x, y, back + 0.02f}, {x + width, y + height, back + 0.02f + depth}));
      x += width + 0.004f;
    }
  }
  for (int i = 0; i < 4; ++i) scene.add_object("books_" + std::to_string(i), books[i], m.books[i]);
  MeshData ceramics;
  ceramics.append(make_lathe({{0.0f, 0.0f}, {0.06f, 0.0f}, {0.06f, 0.0f}, {0.09f, 0.1f}, {0.06f, 0.22f}, {0.06f, 0.22f},
                              {0.0f, 0.22f}}, 48),
                  glm::translate(glm::mat4(1.0f), {-1.2f, top, -kRoom + 0.18f}));
  scene.add_object("shelf_vase", ceramics, m.white_ceramic);

  // A potted plant in the corner between shelf and window wall: a pot and a cluster of leaf balls.
  MeshData pot, leaves;
  pot.append(make_lathe({{0.0f, 0.0f}, {0.14f, 0.0f}, {0.14f, 0.0f}, {0.18f, 0.38f}, {0.18f, 0.38f}, {0.16f, 0.38f},
                         {0.16f, 0.38f}, {0.0f, 0.34f}}, 48),
             glm::translate(glm::mat4(1.0f), {-2.2f, 0.0f, -1.75f}));
  for (int k = 0; k < 9; ++k) {
    const float a = glm::two_pi<float>() * hash01(uint32_t(k), 0, 29), r = 0.2f * hash01(uint32_t(k), 1, 29);
    const glm::vec3 c(-2.2f + r * std::cos(a), 0.6f + 0.5f * hash01(uint32_t(k), 2, 29), -1.75f + r * std::sin(a));
    leaves.append(make_sphere(c, 0.14f + 0.08f * hash01(uint32_t(k), 3, 29), 20, 10));
  }
  scene.add_object("plant_pot", pot, m.pot);
  scene.add_object("plant", leaves, m.leaves);

  // A brass floor lamp (unlit) beside the sofa: base, pole, and a fabric shade.
  MeshData lamp;
  lamp.append(make_cylinder({2.15f, 0.0f, -2.15f}, 0.15f, 0.02f, 32));
  lamp.append(make_cylinder({2.15f, 0.02f, -2.15f}, 0.012f, 1.4f, 16));
  scene.add_object("floor_lamp", lamp, m.metal);
  MeshData shade;
  shade.append(make_lathe({{0.2f, 1.3f}, {0.13f, 1.62f}}, 48), glm::translate(glm::mat4(1.0f), {2.15f, 0.0f, -2.15f}));
  scene.add_object("lamp_shade", shade, m.linen);

  // A picture over the sofa: a lacquered frame and an abstract painting in three fields.
  const float px0 = 0.1f, px1 = 1.5f, py0 = 1.25f, py1 = 2.1f, pz = -kRoom + 0.03f;
  scene.add_object("picture_frame", make_box({px0 - 0.04f, py0 - 0.04f, -kRoom}, {px1 + 0.04f, py1 + 0.04f, pz}), m.picture_frame);
  const glm::vec3 x(1, 0, 0), y(0, 1, 0);
  scene.add_object("canvas_a", make_quad({px0, py0, pz + 0.002f}, 0.55f * x, (py1 - py0) * y), m.canvas_a);
  scene.add_object("canvas_b", make_quad({px0 + 0.55f, py0, pz + 0.002f}, (px1 - px0 - 0.55f) * x, 0.5f * y), m.canvas_b);
  scene.add_object("canvas_c", make_quad({px0 + 0.55f, py0 + 0.5f, pz + 0.002f}, (px1 - px0 - 0.55f) * x, (py1 - py0 - 0.5f) * y),
                   m.canvas_c);
}

}  // namespace

void write_window(const std::string& dir) {
  SceneBuilder scene("window");
  const Materials materials = add_materials(scene);
  add_shell(scene, materials);
  add_sofa(scene, materials);
  add_rug_and_tables(scene, materials);
  add_shelf_and_decor(scene, materials);
  scene.set_camera({1.9f, 1.55f, 2.2f}, {-0.9f, 0.75f, -1.6f}, 1.0f, 16.0f / 9.0f);
  scene.set_render_defaults(false, 960, 540);
  scene.write(dir);
  DaylightSky sky;
  sky.sun_direction = kSunDirection;
  sky.sun_radius = 0.025f;
  sky.sun_radiance = {19000.0f, 17500.0f, 15000.0f};
  sky.ground = {0.9f, 0.95f, 0.7f};
  sky.seed = 99;
  write_environment(dir, paint_equirect(1024, 512, [&](const glm::vec3& d) { return daylight_radiance(sky, d); }));
}

}  // namespace pxf::scenegen
