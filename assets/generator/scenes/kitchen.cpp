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
  int floor, wood, counter, backsplash, wall, ceiling, carcass, metal, whiteCeramic, blueCeramic;
  int greenGlass, clearGlass, redBox, yellowBox, orange, stripLight, panelLight, black;
};

MaterialDesc emitter(const std::string& name, const glm::vec3& color, float strength) {
  MaterialDesc desc = plainMaterial(name, glm::vec3(0.8f));
  desc.emissive = color;
  desc.emissiveStrength = strength;
  return desc;
}

MaterialDesc glassMaterial(const std::string& name, const glm::vec3& tint) {
  MaterialDesc desc = plainMaterial(name, tint, 0.0f);
  desc.transmission = 1.0f;
  desc.ior = 1.5f;
  return desc;
}

Materials addMaterials(SceneBuilder& scene) {
  Materials m{};
  TileStyle floorTiles;  // black and white marble checkerboard, 0.3 m tiles
  floorTiles.colorA = {0.8f, 0.79f, 0.76f};
  floorTiles.colorB = {0.05f, 0.05f, 0.055f};
  floorTiles.veins = 0.35f;
  floorTiles.tileRoughness = 0.2f;
  floorTiles.seed = 5;
  m.floor = scene.addMaterial(addTextureSet(scene, paintTiles(512, floorTiles), "floor_tiles", 0.02f, glm::vec2(1.0f / 1.2f)));
  m.wood = scene.addMaterial(addTextureSet(scene, paintWood(512, 4, {0.62f, 0.42f, 0.24f}, {0.36f, 0.2f, 0.1f}, 41),
                                           "oak", 0.004f));
  m.counter = scene.addMaterial(addTextureSet(scene, paintStone(512, {0.16f, 0.155f, 0.17f}, 51), "granite", 0.004f));
  BrickStyle subway;  // glazed white 15 cm x 7.5 cm tiles, 0.6 m per texture
  subway.rows = 8;
  subway.columns = 4;
  subway.jointWidth = 0.006f;
  subway.palette = {{0.86f, 0.86f, 0.84f}, {0.83f, 0.84f, 0.83f}, {0.88f, 0.87f, 0.84f}};
  subway.mortar = {0.6f, 0.58f, 0.55f};
  subway.brickRoughness = 0.12f;
  subway.pitting = 0.0f;
  subway.seed = 61;
  m.backsplash = scene.addMaterial(addTextureSet(scene, paintBricks(512, subway), "subway_tiles", 0.01f, glm::vec2(1.0f / 0.6f)));
  m.wall = scene.addMaterial(plainMaterial("wall_paint", {0.72f, 0.7f, 0.64f}, 0.85f));
  m.ceiling = scene.addMaterial(plainMaterial("ceiling_paint", {0.8f, 0.8f, 0.78f}, 0.9f));
  m.carcass = scene.addMaterial(plainMaterial("cabinet_carcass", {0.75f, 0.73f, 0.68f}, 0.6f));
  MaterialDesc metal = plainMaterial("brushed_steel", {0.9f, 0.89f, 0.87f}, 0.3f);
  metal.metallic = 1.0f;
  m.metal = scene.addMaterial(metal);
  m.whiteCeramic = scene.addMaterial(plainMaterial("white_ceramic", {0.85f, 0.85f, 0.82f}, 0.12f));
  m.blueCeramic = scene.addMaterial(plainMaterial("blue_ceramic", {0.08f, 0.18f, 0.45f}, 0.2f));
  m.greenGlass = scene.addMaterial(glassMaterial("green_glass", {0.55f, 0.85f, 0.55f}));
  m.clearGlass = scene.addMaterial(glassMaterial("clear_glass", glm::vec3(1.0f)));
  m.redBox = scene.addMaterial(plainMaterial("red_carton", {0.65f, 0.08f, 0.06f}, 0.7f));
  m.yellowBox = scene.addMaterial(plainMaterial("yellow_carton", {0.8f, 0.6f, 0.1f}, 0.7f));
  m.orange = scene.addMaterial(plainMaterial("orange_peel", {0.8f, 0.33f, 0.04f}, 0.45f));
  m.stripLight = scene.addMaterial(emitter("led_strip", {1.0f, 0.82f, 0.6f}, 12.0f));
  m.panelLight = scene.addMaterial(emitter("ceiling_panel", {1.0f, 0.96f, 0.9f}, 8.0f));
  m.black = scene.addMaterial(plainMaterial("black_plastic", glm::vec3(0.03f), 0.5f));
  return m;
}

void addRoom(SceneBuilder& scene, const Materials& m) {
  const glm::vec3 x(1, 0, 0), y(0, 1, 0), z(0, 0, 1);
  const float w = 2 * kRoomX, d = 2 * kRoomZ, h = kRoomY;
  scene.addObject("floor", makeQuad({-kRoomX, 0, kRoomZ}, w * x, -d * z, {w, d}), m.floor);
  // The ceiling is the recess above the soffit; the soffit frames it.
  scene.addObject("ceiling", makeQuad({-kRoomX, h, -kRoomZ}, w * x, d * z, {w, d}), m.ceiling);
  MeshData walls;
  walls.append(makeQuad({-kRoomX, 0, -kRoomZ}, w * x, h * y));   // back, faces +z
  walls.append(makeQuad({kRoomX, 0, kRoomZ}, -w * x, h * y));    // front, faces -z
  walls.append(makeQuad({-kRoomX, 0, kRoomZ}, -d * z, h * y));   // left, faces +x
  walls.append(makeQuad({kRoomX, 0, -kRoomZ}, d * z, h * y));    // right, faces -x
  scene.addObject("walls", walls, m.wall);
  // Backsplash between counter and wall cabinets, 1 cm proud of the back wall.
  const float splashHeight = kWallCabinetBottom - kCounterTop;
  scene.addObject("backsplash", makeQuad({-kRoomX, kCounterTop, -kRoomZ + 0.01f}, w * x, splashHeight * y, {w, splashHeight}),
                  m.backsplash);
  // The soffit: a frame hanging 0.3 m from the ceiling along all four walls.
  MeshData soffit;
  const float b = kSoffitBottom, s = kSoffitWidth;
  soffit.append(makeBox({-kRoomX, b, -kRoomZ}, {kRoomX, h, -kRoomZ + s}));
  soffit.append(makeBox({-kRoomX, b, kRoomZ - s}, {kRoomX, h, kRoomZ}));
  soffit.append(makeBox({-kRoomX, b, -kRoomZ + s}, {-kRoomX + s, h, kRoomZ - s}));
  soffit.append(makeBox({kRoomX - s, b, -kRoomZ + s}, {kRoomX, h, kRoomZ - s}));
  scene.addObject("soffit", soffit, m.ceiling);
  // Two light panels in the recess, 5 mm under the ceiling, facing down.
  MeshData panels;
  for (float px : {-1.4f, 0.2f})
    panels.append(makeQuad({px, h - 0.005f, -0.35f}, 1.2f * x, 0.7f * z));
  scene.addObject("ceiling_panels", panels, m.panelLight);
}

// Doors of width `doorWidth` tiling [x0, x1], 2 cm proud of the carcass front at z = front, with
// 3 mm gaps; each door gets a steel bar handle placed at `handleY`.
void addDoors(MeshData& doors, MeshData& handles, float x0, float x1, float y0, float y1, float front,
              int count, float handleY) {
  const float width = (x1 - x0) / float(count);
  for (int i = 0; i < count; ++i) {
    const float a = x0 + width * float(i) + 0.003f, b = a + width - 0.006f;
    doors.append(makeBox({a, y0 + 0.003f, front}, {b, y1 - 0.003f, front + 0.02f}));
    const float hx = (i % 2 == 0) ? b - 0.06f : a + 0.04f;
    handles.append(makeBox({hx, handleY - 0.07f, front + 0.02f}, {hx + 0.02f, handleY + 0.07f, front + 0.045f}));
  }
}

void addCabinets(SceneBuilder& scene, const Materials& m) {
  MeshData carcass, doors, handles, counter;
  const float back = -kRoomZ;
  // Base run along the back wall, with a toe kick.
  carcass.append(makeBox({-2.45f, 0.1f, back}, {1.6f, kCounterTop - 0.04f, back + 0.58f}));
  carcass.append(makeBox({-2.45f, 0.0f, back}, {1.6f, 0.1f, back + 0.52f}));
  addDoors(doors, handles, -2.45f, 1.6f, 0.1f, kCounterTop - 0.04f, back + 0.58f, 7, 0.72f);
  counter.append(makeBox({-2.48f, kCounterTop - 0.04f, back}, {1.63f, kCounterTop, back + 0.62f}));
  // Wall cabinets left and right of the open shelves; a 4 cm lip at the front hides the strips.
  const float front = back + kWallCabinetDepth;
  for (auto [x0, x1, doorCount] : {std::tuple{-2.45f, -0.75f, 3}, std::tuple{0.35f, 1.6f, 2}}) {
    carcass.append(makeBox({x0, kWallCabinetBottom, back}, {x1, kWallCabinetTop, front}));
    carcass.append(makeBox({x0, kWallCabinetBottom - 0.04f, front - 0.02f}, {x1, kWallCabinetBottom, front}));
    addDoors(doors, handles, x0, x1, kWallCabinetBottom - 0.04f, kWallCabinetTop, front, doorCount,
             kWallCabinetBottom + 0.06f);
  }
  // Island in the middle of the room.
  carcass.append(makeBox({-0.9f, 0.0f, 0.1f}, {0.9f, kCounterTop - 0.04f, 0.8f}));
  counter.append(makeBox({-0.95f, kCounterTop - 0.04f, 0.05f}, {0.95f, kCounterTop, 0.85f}));
  addDoors(doors, handles, -0.9f, 0.9f, 0.1f, kCounterTop - 0.04f, 0.8f, 4, 0.72f);
  scene.addObject("cabinet_carcass", carcass, m.carcass);
  scene.addObject("cabinet_doors", doors, m.wood);
  scene.addObject("handles", handles, m.metal);
  scene.addObject("countertops", counter, m.counter);

  // Open oak shelves between the wall cabinets.
  MeshData shelves;
  for (float sy : {1.5f, 1.9f}) shelves.append(makeBox({-0.72f, sy, back}, {0.32f, sy + 0.03f, back + 0.28f}));
  scene.addObject("shelves", shelves, m.wood);

  // LED strips under the wall cabinets, behind the lip, emitting downwards.
  MeshData strips;
  for (auto [x0, x1] : {std::pair{-2.4f, -0.8f}, std::pair{0.4f, 1.55f}})
    strips.append(makeQuad({x0, kWallCabinetBottom - 0.002f, front - 0.07f}, {x1 - x0, 0, 0}, {0, 0, 0.025f}));
  scene.addObject("led_strips", strips, m.stripLight);
}

MeshData makeBowl(const glm::vec3& base, float radius, float height) {
  std::vector<glm::vec2> profile = {{0.0f, 0.0f}, {radius * 0.45f, 0.0f}, {radius * 0.45f, 0.0f},
                                    {radius * 0.8f, height * 0.35f}, {radius, height}, {radius * 0.93f, height},
                                    {radius * 0.73f, height * 0.4f}, {radius * 0.4f, height * 0.1f},
                                    {0.0f, height * 0.1f}};
  MeshData bowl;
  bowl.append(makeLathe(profile, 48), glm::translate(glm::mat4(1.0f), base));
  return bowl;
}

MeshData makeBottle(const glm::vec3& base, float radius, float height) {
  const float r = radius, h = height;
  std::vector<glm::vec2> profile = {{0.0f, 0.0f},    {r, 0.0f},         {r, 0.0f},         {r, 0.62f * h},
                                    {0.9f * r, 0.72f * h}, {0.32f * r, 0.85f * h}, {0.3f * r, h},
                                    {0.3f * r, h},   {0.0f, h}};
  MeshData bottle;
  bottle.append(makeLathe(profile, 32), glm::translate(glm::mat4(1.0f), base));
  return bottle;
}

void addObjects(SceneBuilder& scene, const Materials& m) {
  const float top = kCounterTop;
  const float counterZ = -kRoomZ + 0.32f;
  auto back = [](float depth) { return -kRoomZ + depth; };  // z at `depth` from the back wall
  MeshData white, blue, green, clear, red, yellow, fruit, steel, board;
  white.append(makeBowl({-1.9f, top, counterZ}, 0.14f, 0.09f));
  blue.append(makeBowl({0.0f, top, 0.45f}, 0.2f, 0.11f));                     // fruit bowl on the island
  for (auto [ox, oz] : {std::pair{-0.06f, 0.02f}, std::pair{0.07f, 0.04f}, std::pair{0.0f, -0.07f}})
    fruit.append(makeSphere({ox, top + 0.052f, 0.45f + oz}, 0.04f, 24, 12));
  fruit.append(makeSphere({0.0f, top + 0.118f, 0.45f}, 0.04f, 24, 12));
  green.append(makeBottle({-0.3f, top, counterZ - 0.08f}, 0.038f, 0.32f));
  green.append(makeBottle({-0.18f, top, counterZ - 0.12f}, 0.034f, 0.28f));
  clear.append(makeBottle({0.55f, top, 0.3f}, 0.045f, 0.3f));
  // Jars on the shelves: closed cylinders of clear glass; plates stacked beside them.
  for (int i = 0; i < 3; ++i) clear.append(makeCylinder({-0.6f + 0.13f * float(i), 1.53f, back(0.14f)}, 0.05f, 0.16f, 32));
  for (int i = 0; i < 4; ++i) white.append(makeCylinder({0.12f, 1.53f + 0.018f * float(i), back(0.14f)}, 0.12f, 0.012f, 48));
  for (int i = 0; i < 3; ++i) blue.append(makeCylinder({-0.55f + 0.2f * float(i), 1.93f, back(0.13f)}, 0.055f, 0.1f, 32));
  // Cereal boxes and a steel pot with lid and handles.
  red.append(makeBox({1.0f, top, -kRoomZ + 0.05f}, {1.2f, top + 0.3f, -kRoomZ + 0.12f}));
  yellow.append(makeBox({1.25f, top, -kRoomZ + 0.04f}, {1.42f, top + 0.26f, -kRoomZ + 0.11f}));
  steel.append(makeCylinder({-1.1f, top, counterZ}, 0.12f, 0.15f, 48));
  steel.append(makeCylinder({-1.1f, top + 0.15f, counterZ}, 0.125f, 0.01f, 48));
  steel.append(makeBox({-1.27f, top + 0.11f, counterZ - 0.015f}, {-1.12f, top + 0.125f, counterZ + 0.015f}));
  steel.append(makeBox({-0.98f + 0.0f, top + 0.11f, counterZ - 0.015f}, {-0.93f, top + 0.125f, counterZ + 0.015f}));
  board.append(makeBox({-1.75f, top, counterZ - 0.05f}, {-1.35f, top + 0.02f, counterZ + 0.2f}));
  scene.addObject("white_ceramics", white, m.whiteCeramic);
  scene.addObject("blue_ceramics", blue, m.blueCeramic);
  scene.addObject("fruit", fruit, m.orange);
  scene.addObject("green_bottles", green, m.greenGlass);
  scene.addObject("glassware", clear, m.clearGlass);
  scene.addObject("red_box", red, m.redBox);
  scene.addObject("yellow_box", yellow, m.yellowBox);
  scene.addObject("pot", steel, m.metal);
  scene.addObject("cutting_board", board, m.wood);
}

}  // namespace

bool writeKitchen(const std::string& dir, std::string* error) {
  SceneBuilder scene("kitchen");
  const Materials materials = addMaterials(scene);
  addRoom(scene, materials);
  addCabinets(scene, materials);
  addObjects(scene, materials);
  scene.setCamera({2.2f, 1.55f, 1.85f}, {-0.7f, 1.05f, -1.6f}, 0.95f, 16.0f / 9.0f);
  scene.setRenderDefaults(false, 960, 540);
  return scene.write(dir, error);
}

}  // namespace pxf::scenegen
