// A kitchen interior, 5 m x 4 m x 2.7 m: base and wall cabinets with wood doors, a granite
// counter, a subway-tile backsplash, open shelves, an island, and objects (bowls, bottles, jars,
// boxes, a pot, fruit). Only area lights, all partly occluded so direct light has soft penumbrae:
// LED strips recessed under the wall cabinets behind a front lip, and ceiling panels in a recess
// behind a soffit.
#include <glm/gtc/matrix_transform.hpp>
#include <tuple>

#include "../gltf_builder.h"
#include "../procedural.h"
#include "../scenes.h"

namespace pxf::scenegen {
namespace {

// Room: x in [-2.5, 2.5], z in [-2, 2] (back wall at z = -2), y in [0, 2.7].
constexpr float kRoomX = 2.5f, kRoomZ = 2.0f, kRoomY = 2.7f;
constexpr float kCounterTop = 0.9f;
constexpr float kWallCabinetBottom = 1.45f, kWallCabinetTop = 2.2f, kWallCabinetDepth = 0.35f;
constexpr float kSoffitBottom = 2.4f, kSoffitWidth = 0.7f;

struct Materials {
  int floor, wood, counter, backsplash, wall, ceiling, carcass, metal, white_ceramic, blue_ceramic;
  int green_glass, clear_glass, red_box, yellow_box, orange, strip_light, panel_light, black;
};

MaterialDesc emitter(const std::string& name, const glm::vec3& color, float strength) {
  MaterialDesc desc = plain_material(name, glm::vec3(0.8f));
  desc.emissive = color;
  desc.emissive_strength = strength;
  return desc;
}

MaterialDesc glass_material(const std::string& name, const glm::vec3& tint) {
  MaterialDesc desc = plain_material(name, tint, 0.0f);
  desc.transmission = 1.0f;
  desc.ior = 1.5f;
  return desc;
}

Materials add_materials(SceneBuilder& scene) {
  Materials m{};
  TileStyle floor_tiles;  // black and white marble checkerboard, 0.3 m tiles
  floor_tiles.color_a = {0.8f, 0.79f, 0.76f};
  floor_tiles.color_b = {0.05f, 0.05f, 0.055f};
  floor_tiles.veins = 0.35f;
  floor_tiles.tile_roughness = 0.2f;
  floor_tiles.seed = 5;
  m.floor = scene.add_material(add_texture_set(scene, paint_tiles(512, floor_tiles), "floor_tiles", 0.02f, glm::vec2(1.0f / 1.2f)));
  m.wood = scene.add_material(add_texture_set(scene, paint_wood(512, 4, {0.62f, 0.42f, 0.24f}, {0.36f, 0.2f, 0.1f}, 41),
                                              "oak", 0.004f));
  m.counter = scene.add_material(add_texture_set(scene, paint_stone(512, {0.16f, 0.155f, 0.17f}, 51), "granite", 0.004f));
  BrickStyle subway;  // glazed white 15 cm x 7.5 cm tiles, 0.6 m per texture
  subway.rows = 8;
  subway.columns = 4;
  subway.joint_width = 0.006f;
  subway.palette = {{0.86f, 0.86f, 0.84f}, {0.83f, 0.84f, 0.83f}, {0.88f, 0.87f, 0.84f}};
  subway.mortar = {0.6f, 0.58f, 0.55f};
  subway.brick_roughness = 0.12f;
  subway.pitting = 0.0f;
  subway.seed = 61;
  m.backsplash = scene.add_material(add_texture_set(scene, paint_bricks(512, subway), "subway_tiles", 0.01f, glm::vec2(1.0f / 0.6f)));
  m.wall = scene.add_material(plain_material("wall_paint", {0.72f, 0.7f, 0.64f}, 0.85f));
  m.ceiling = scene.add_material(plain_material("ceiling_paint", {0.8f, 0.8f, 0.78f}, 0.9f));
  m.carcass = scene.add_material(plain_material("cabinet_carcass", {0.75f, 0.73f, 0.68f}, 0.6f));
  MaterialDesc metal = plain_material("brushed_steel", {0.9f, 0.89f, 0.87f}, 0.3f);
  metal.metallic = 1.0f;
  m.metal = scene.add_material(metal);
  m.white_ceramic = scene.add_material(plain_material("white_ceramic", {0.85f, 0.85f, 0.82f}, 0.12f));
  m.blue_ceramic = scene.add_material(plain_material("blue_ceramic", {0.08f, 0.18f, 0.45f}, 0.2f));
  m.green_glass = scene.add_material(glass_material("green_glass", {0.55f, 0.85f, 0.55f}));
  m.clear_glass = scene.add_material(glass_material("clear_glass", glm::vec3(1.0f)));
  m.red_box = scene.add_material(plain_material("red_carton", {0.65f, 0.08f, 0.06f}, 0.7f));
  m.yellow_box = scene.add_material(plain_material("yellow_carton", {0.8f, 0.6f, 0.1f}, 0.7f));
  m.orange = scene.add_material(plain_material("orange_peel", {0.8f, 0.33f, 0.04f}, 0.45f));
  m.strip_light = scene.add_material(emitter("led_strip", {1.0f, 0.82f, 0.6f}, 12.0f));
  m.panel_light = scene.add_material(emitter("ceiling_panel", {1.0f, 0.96f, 0.9f}, 8.0f));
  m.black = scene.add_material(plain_material("black_plastic", glm::vec3(0.03f), 0.5f));
  return m;
}

void add_room(SceneBuilder& scene, const Materials& m) {
  const glm::vec3 x(1, 0, 0), y(0, 1, 0), z(0, 0, 1);
  const float w = 2 * kRoomX, d = 2 * kRoomZ, h = kRoomY;
  scene.add_object("floor", make_quad({-kRoomX, 0, kRoomZ}, w * x, -d * z, {w, d}), m.floor);
  // The ceiling is the recess above the soffit; the soffit frames it.
  scene.add_object("ceiling", make_quad({-kRoomX, h, -kRoomZ}, w * x, d * z, {w, d}), m.ceiling);
  MeshData walls;
  walls.append(make_quad({-kRoomX, 0, -kRoomZ}, w * x, h * y));   // back, faces +z
  walls.append(make_quad({kRoomX, 0, kRoomZ}, -w * x, h * y));    // front, faces -z
  walls.append(make_quad({-kRoomX, 0, kRoomZ}, -d * z, h * y));   // left, faces +x
  walls.append(make_quad({kRoomX, 0, -kRoomZ}, d * z, h * y));    // right, faces -x
  scene.add_object("walls", walls, m.wall);
  // Backsplash between counter and wall cabinets, 1 cm proud of the back wall.
  const float splash_height = kWallCabinetBottom - kCounterTop;
  scene.add_object("backsplash", make_quad({-kRoomX, kCounterTop, -kRoomZ + 0.01f}, w * x, splash_height * y, {w, splash_height}),
                   m.backsplash);
  // The soffit: a frame hanging 0.3 m from the ceiling along all four walls.
  MeshData soffit;
  const float b = kSoffitBottom, s = kSoffitWidth;
  soffit.append(make_box({-kRoomX, b, -kRoomZ}, {kRoomX, h, -kRoomZ + s}));
  soffit.append(make_box({-kRoomX, b, kRoomZ - s}, {kRoomX, h, kRoomZ}));
  soffit.append(make_box({-kRoomX, b, -kRoomZ + s}, {-kRoomX + s, h, kRoomZ - s}));
  soffit.append(make_box({kRoomX - s, b, -kRoomZ + s}, {kRoomX, h, kRoomZ - s}));
  scene.add_object("soffit", soffit, m.ceiling);
  // Two light panels in the recess, 5 mm under the ceiling, facing down.
  MeshData panels;
  for (float px : {-1.4f, 0.2f})
    panels.append(make_quad({px, h - 0.005f, -0.35f}, 1.2f * x, 0.7f * z));
  scene.add_object("ceiling_panels", panels, m.panel_light);
}

// Doors of width `doorWidth` tiling [x0, x1], 2 cm proud of the carcass front at z = front, with
// 3 mm gaps; each door gets a steel bar handle placed at `handle_y`.
void add_doors(MeshData& doors, MeshData& handles, float x0, float x1, float y0, float y1, float front,
               int count, float handle_y) {
  const float width = (x1 - x0) / float(count);
  for (int i = 0; i < count; ++i) {
    const float a = x0 + width * float(i) + 0.003f, b = a + width - 0.006f;
    doors.append(make_box({a, y0 + 0.003f, front}, {b, y1 - 0.003f, front + 0.02f}));
    const float hx = (i % 2 == 0) ? b - 0.06f : a + 0.04f;
    handles.append(make_box({hx, handle_y - 0.07f, front + 0.02f}, {hx + 0.02f, handle_y + 0.07f, front + 0.045f}));
  }
}

void add_cabinets(SceneBuilder& scene, const Materials& m) {
  MeshData carcass, doors, handles, counter;
  const float back = -kRoomZ;
  // Base run along the back wall, with a toe kick.
  carcass.append(make_box({-2.45f, 0.1f, back}, {1.6f, kCounterTop - 0.04f, back + 0.58f}));
  carcass.append(make_box({-2.45f, 0.0f, back}, {1.6f, 0.1f, back + 0.52f}));
  add_doors(doors, handles, -2.45f, 1.6f, 0.1f, kCounterTop - 0.04f, back + 0.58f, 7, 0.72f);
  counter.append(make_box({-2.48f, kCounterTop - 0.04f, back}, {1.63f, kCounterTop, back + 0.62f}));
  // Wall cabinets left and right of the open shelves; a 4 cm lip at the front hides the strips.
  const float front = back + kWallCabinetDepth;
  for (auto [x0, x1, door_count] : {std::tuple{-2.45f, -0.75f, 3}, std::tuple{0.35f, 1.6f, 2}}) {
    carcass.append(make_box({x0, kWallCabinetBottom, back}, {x1, kWallCabinetTop, front}));
    carcass.append(make_box({x0, kWallCabinetBottom - 0.04f, front - 0.02f}, {x1, kWallCabinetBottom, front}));
    add_doors(doors, handles, x0, x1, kWallCabinetBottom - 0.04f, kWallCabinetTop, front, door_count,
              kWallCabinetBottom + 0.06f);
  }
  // Island in the middle of the room.
  carcass.append(make_box({-0.9f, 0.0f, 0.1f}, {0.9f, kCounterTop - 0.04f, 0.8f}));
  counter.append(make_box({-0.95f, kCounterTop - 0.04f, 0.05f}, {0.95f, kCounterTop, 0.85f}));
  add_doors(doors, handles, -0.9f, 0.9f, 0.1f, kCounterTop - 0.04f, 0.8f, 4, 0.72f);
  scene.add_object("cabinet_carcass", carcass, m.carcass);
  scene.add_object("cabinet_doors", doors, m.wood);
  scene.add_object("handles", handles, m.metal);
  scene.add_object("countertops", counter, m.counter);

  // Open oak shelves between the wall cabinets.
  MeshData shelves;
  for (float sy : {1.5f, 1.9f}) shelves.append(make_box({-0.72f, sy, back}, {0.32f, sy + 0.03f, back + 0.28f}));
  scene.add_object("shelves", shelves, m.wood);

  // LED strips under the wall cabinets, behind the lip, emitting downwards.
  MeshData strips;
  for (auto [x0, x1] : {std::pair{-2.4f, -0.8f}, std::pair{0.4f, 1.55f}})
    strips.append(make_quad({x0, kWallCabinetBottom - 0.002f, front - 0.07f}, {x1 - x0, 0, 0}, {0, 0, 0.025f}));
  scene.add_object("led_strips", strips, m.strip_light);
}

MeshData make_bowl(const glm::vec3& base, float radius, float height) {
  std::vector<glm::vec2> profile = {{0.0f, 0.0f}, {radius * 0.45f, 0.0f}, {radius * 0.45f, 0.0f},
                                    {radius * 0.8f, height * 0.35f}, {radius, height}, {radius * 0.93f, height},
                                    {radius * 0.73f, height * 0.4f}, {radius * 0.4f, height * 0.1f},
                                    {0.0f, height * 0.1f}};
  MeshData bowl;
  bowl.append(make_lathe(profile, 48), glm::translate(glm::mat4(1.0f), base));
  return bowl;
}

MeshData make_bottle(const glm::vec3& base, float radius, float height) {
  const float r = radius, h = height;
  std::vector<glm::vec2> profile = {{0.0f, 0.0f},    {r, 0.0f},         {r, 0.0f},         {r, 0.62f * h},
                                    {0.9f * r, 0.72f * h}, {0.32f * r, 0.85f * h}, {0.3f * r, h},
                                    {0.3f * r, h},   {0.0f, h}};
  MeshData bottle;
  bottle.append(make_lathe(profile, 32), glm::translate(glm::mat4(1.0f), base));
  return bottle;
}

void add_objects(SceneBuilder& scene, const Materials& m) {
  const float top = kCounterTop;
  const float counter_z = -kRoomZ + 0.32f;
  auto back = [](float depth) { return -kRoomZ + depth; };  // z at `depth` from the back wall
  MeshData white, blue, green, clear, red, yellow, fruit, steel, board;
  white.append(make_bowl({-1.9f, top, counter_z}, 0.14f, 0.09f));
  blue.append(make_bowl({0.0f, top, 0.45f}, 0.2f, 0.11f));                     // fruit bowl on the island
  for (auto [ox, oz] : {std::pair{-0.06f, 0.02f}, std::pair{0.07f, 0.04f}, std::pair{0.0f, -0.07f}})
    fruit.append(make_sphere({ox, top + 0.052f, 0.45f + oz}, 0.04f, 24, 12));
  fruit.append(make_sphere({0.0f, top + 0.118f, 0.45f}, 0.04f, 24, 12));
  green.append(make_bottle({-0.3f, top, counter_z - 0.08f}, 0.038f, 0.32f));
  green.append(make_bottle({-0.18f, top, counter_z - 0.12f}, 0.034f, 0.28f));
  clear.append(make_bottle({0.55f, top, 0.3f}, 0.045f, 0.3f));
  // Jars on the shelves: closed cylinders of clear glass; plates stacked beside them.
  for (int i = 0; i < 3; ++i) clear.append(make_cylinder({-0.6f + 0.13f * float(i), 1.53f, back(0.14f)}, 0.05f, 0.16f, 32));
  for (int i = 0; i < 4; ++i) white.append(make_cylinder({0.12f, 1.53f + 0.018f * float(i), back(0.14f)}, 0.12f, 0.012f, 48));
  for (int i = 0; i < 3; ++i) blue.append(make_cylinder({-0.55f + 0.2f * float(i), 1.93f, back(0.13f)}, 0.055f, 0.1f, 32));
  // Cereal boxes and a steel pot with lid and handles.
  red.append(make_box({1.0f, top, -kRoomZ + 0.05f}, {1.2f, top + 0.3f, -kRoomZ + 0.12f}));
  yellow.append(make_box({1.25f, top, -kRoomZ + 0.04f}, {1.42f, top + 0.26f, -kRoomZ + 0.11f}));
  steel.append(make_cylinder({-1.1f, top, counter_z}, 0.12f, 0.15f, 48));
  steel.append(make_cylinder({-1.1f, top + 0.15f, counter_z}, 0.125f, 0.01f, 48));
  steel.append(make_box({-1.27f, top + 0.11f, counter_z - 0.015f}, {-1.12f, top + 0.125f, counter_z + 0.015f}));
  steel.append(make_box({-0.98f + 0.0f, top + 0.11f, counter_z - 0.015f}, {-0.93f, top + 0.125f, counter_z + 0.015f}));
  board.append(make_box({-1.75f, top, counter_z - 0.05f}, {-1.35f, top + 0.02f, counter_z + 0.2f}));
  scene.add_object("white_ceramics", white, m.white_ceramic);
  scene.add_object("blue_ceramics", blue, m.blue_ceramic);
  scene.add_object("fruit", fruit, m.orange);
  scene.add_object("green_bottles", green, m.green_glass);
  scene.add_object("glassware", clear, m.clear_glass);
  scene.add_object("red_box", red, m.red_box);
  scene.add_object("yellow_box", yellow, m.yellow_box);
  scene.add_object("pot", steel, m.metal);
  scene.add_object("cutting_board", board, m.wood);
}

}  // namespace

void write_kitchen(const std::string& dir) {
  SceneBuilder scene("kitchen");
  const Materials materials = add_materials(scene);
  add_room(scene, materials);
  add_cabinets(scene, materials);
  add_objects(scene, materials);
  scene.set_camera({2.2f, 1.55f, 1.85f}, {-0.7f, 1.05f, -1.6f}, 0.95f, 16.0f / 9.0f);
  scene.set_render_defaults(false, 960, 540);
  scene.write(dir);
}

}  // namespace pxf::scenegen
