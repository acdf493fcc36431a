// Procedural surface materials (tiles, bricks, stone, wood, iron grille) painted as texture sets:
// linear albedo, height (for the normal map), roughness and an optional specular map. All
// patterns tile seamlessly, so the REPEAT sampler hides the texture borders.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "gltf_builder.h"
#include "texture.h"

namespace pxf::scenegen {

struct TextureSet {
  Image albedo;     // RGB or RGBA (A = alpha for MASK materials), linear
  Image height;     // 1 channel, any range; slopes scaled by normal_strength
  Image roughness;  // 1 channel
  Image specular;   // 1 channel or empty (no KHR_materials_specular texture)
  Image metallic;   // 1 channel or empty (add_texture_set's `metallic` everywhere)
};

struct TileStyle {
  int tiles_per_side = 4;
  float grout_width = 0.03f;  // fraction of a tile
  glm::vec3 color_a{0.75f, 0.7f, 0.62f};
  glm::vec3 color_b{0.45f, 0.2f, 0.12f};
  bool checker = true;
  float veins = 0.5f;        // marble veining amount, 0 for plain glazed tiles
  glm::vec3 grout_color{0.32f, 0.3f, 0.28f};
  float tile_roughness = 0.3f;
  uint32_t seed = 1;
};

TextureSet paint_tiles(int size, const TileStyle& style);
struct BrickStyle {
  int rows = 14;      // courses per texture
  int columns = 4;    // bricks per course
  float joint_width = 0.004f;  // half width of a joint, texture units
  std::vector<glm::vec3> palette{{0.50f, 0.18f, 0.10f}, {0.38f, 0.12f, 0.07f}, {0.56f, 0.28f, 0.15f},
                                 {0.30f, 0.11f, 0.07f}, {0.46f, 0.22f, 0.14f}};
  glm::vec3 mortar{0.55f, 0.52f, 0.47f};
  float brick_roughness = 0.8f;  // glazed tiles: low
  float pitting = 1.0f;         // 0 for a smooth glaze
  uint32_t seed = 21;
};

TextureSet paint_bricks(int size, const BrickStyle& style);
TextureSet paint_stone(int size, glm::vec3 tint, uint32_t seed);
TextureSet paint_wood(int size, int planks, glm::vec3 light, glm::vec3 dark, uint32_t seed);
// Overlapping fish scales (`rows` x `rows` per tile), glazed in two colors.
TextureSet paint_scales(int size, int rows, uint32_t seed);
// Painted hull panels (two rows of two per tile, the lower row offset): recessed seams, rivets,
// off-white stencilled markings, grime streaks running down, an orange-peel finish and chipped paint that
// shows bare metal (the metallic map is 1 there). `accent` paints about a quarter of the panels.
TextureSet paint_hull_panels(int size, glm::vec3 paint_color, glm::vec3 accent, uint32_t seed);
// Brushed metal: fine streaks along x, blotchy wear and scattered scratches (rougher, recessed).
// `tint` is the metal's albedo (F0).
TextureSet paint_brushed_metal(int size, glm::vec3 tint, uint32_t seed);
// A smooth metal or glass face with smudges, fingerprints and dust: mostly roughness detail.
TextureSet paint_smudged(int size, glm::vec3 tint, uint32_t seed);
// A plain-weave fabric of `threads` x `threads` threads per tile, near white (tint it with the
// material's base colour).
TextureSet paint_fabric(int size, int threads, uint32_t seed);
// A woven rug covering the texture once: borders and a diamond lattice in four colours, deep pile.
TextureSet paint_rug(int size, uint32_t seed);
// Trowelled plaster: faint blotches and a soft relief.
TextureSet paint_plaster(int size, glm::vec3 color, uint32_t seed);
// An ornamental wrought-iron grille: albedo alpha is 1 on the bars, 0 in the openings.
TextureSet paint_grille(int size, int bars);

// Adds the set's PNGs (<stem>_basecolor, _normal, _mr) and returns a material using them;
// the specular map, if any, goes into the A channel of the _mr texture.
MaterialDesc add_texture_set(SceneBuilder& scene, const TextureSet& set, const std::string& stem,
                             float normal_strength, glm::vec2 uv_scale = glm::vec2(1.0f), float metallic = 0.0f);

}  // namespace pxf::scenegen
