#include "procedural.h"

#include <algorithm>
#include <cmath>
#include <glm/gtc/constants.hpp>

namespace pxf::scenegen {
namespace {

float fract(float v) { return v - std::floor(v); }

float smoothstep(float e0, float e1, float x) {
  const float t = std::clamp((x - e0) / (e1 - e0), 0.0f, 1.0f);
  return t * t * (3.0f - 2.0f * t);
}

// Storage for one texel of every map, set by the painters below.
struct Texel {
  glm::vec3 albedo{0.5f};
  float alpha = 1.0f;
  float height = 0.0f;
  float roughness = 0.5f;
  float specular = 0.5f;
  float metallic = 0.0f;  // kept only by painters called with_metallic
};

template <typename Painter>
TextureSet paint(int size, bool with_alpha, bool with_specular, Painter painter, bool with_metallic = false) {
  TextureSet set;
  set.albedo = with_alpha ? Image::rgba(size, size) : Image::rgb(size, size);
  set.height = Image::gray(size, size);
  set.roughness = Image::gray(size, size);
  if (with_specular) set.specular = Image::gray(size, size);
  if (with_metallic) set.metallic = Image::gray(size, size);
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      Texel t = painter((x + 0.5f) / size, (y + 0.5f) / size);
      set.albedo.at(x, y, 0) = t.albedo.r, set.albedo.at(x, y, 1) = t.albedo.g, set.albedo.at(x, y, 2) = t.albedo.b;
      if (with_alpha) set.albedo.at(x, y, 3) = t.alpha;
      set.height.at(x, y, 0) = t.height;
      set.roughness.at(x, y, 0) = std::clamp(t.roughness, 0.02f, 1.0f);
      if (with_specular) set.specular.at(x, y, 0) = std::clamp(t.specular, 0.0f, 1.0f);
      if (with_metallic) set.metallic.at(x, y, 0) = std::clamp(t.metallic, 0.0f, 1.0f);
    }
  }
  return set;
}

// Per-cell random color variation around `base`.
glm::vec3 vary(const glm::vec3& base, float amount, uint32_t cx, uint32_t cy, uint32_t seed) {
  const float brightness = 1.0f + amount * (2.0f * hash01(cx, cy, seed) - 1.0f);
  const float warmth = amount * 0.5f * (2.0f * hash01(cx, cy, seed + 7) - 1.0f);
  return glm::clamp(base * brightness * glm::vec3(1.0f + warmth, 1.0f, 1.0f - warmth), 0.0f, 1.0f);
}


// Value noise on a px x py lattice over the tile (periodic in both), for streaks: a lattice much
// finer in y than in x draws lines along x. (x, y) in [0, 1).
float streak_noise(float x, float y, int px, int py, uint32_t seed) {
  const float u = x * float(px), v = y * float(py);
  const float fu = std::floor(u), fv = std::floor(v);
  const int x0 = ((int(fu) % px) + px) % px, y0 = ((int(fv) % py) + py) % py;
  const int x1 = (x0 + 1) % px, y1 = (y0 + 1) % py;
  const float tx = smoothstep(0.0f, 1.0f, u - fu), ty = smoothstep(0.0f, 1.0f, v - fv);
  const float a = hash01(x0, y0, seed), b = hash01(x1, y0, seed);
  const float c = hash01(x0, y1, seed), d = hash01(x1, y1, seed);
  return glm::mix(glm::mix(a, b, tx), glm::mix(c, d, tx), ty);
}

// Distance from p to the segment a..a+e on the unit torus (segments shorter than half the tile).
float periodic_segment_distance(glm::vec2 p, glm::vec2 a, glm::vec2 e) {
  glm::vec2 d = p - a;
  d -= glm::floor(d + 0.5f);  // nearest image of p around a
  const float t = std::clamp(glm::dot(d, e) / glm::dot(e, e), 0.0f, 1.0f);
  return glm::length(d - t * e);
}

// Short random scratches: 1 on a scratch, 0 elsewhere (antialiased over `width`).
float scratches(glm::vec2 p, int count, float max_length, float width, uint32_t seed) {
  float mask = 0.0f;
  for (int k = 0; k < count; ++k) {
    const glm::vec2 a(hash01(k, 0, seed), hash01(k, 1, seed));
    const float angle = hash01(k, 2, seed) * glm::pi<float>();
    const float length = max_length * (0.3f + 0.7f * hash01(k, 3, seed));
    const glm::vec2 e = length * glm::vec2(std::cos(angle), std::sin(angle));
    const float w = width * (0.5f + hash01(k, 4, seed));
    mask = std::max(mask, 1.0f - smoothstep(0.5f * w, w, periodic_segment_distance(p, a, e)));
  }
  return mask;
}

}  // namespace

TextureSet paint_tiles(int size, const TileStyle& s) {
  return paint(size, false, false, [&](float x, float y) {
    const float gx = x * s.tiles_per_side, gy = y * s.tiles_per_side;
    const int ix = int(gx), iy = int(gy);
    const float fx = fract(gx), fy = fract(gy);
    const float edge = std::min(std::min(fx, 1.0f - fx), std::min(fy, 1.0f - fy));
    const float tile_mask = smoothstep(s.grout_width, s.grout_width * 2.0f, edge);
    const float grain = tileable_fbm(x, y, 8, 5, 0.55f, s.seed);
    const float fine = tileable_fbm(x, y, 64, 3, 0.5f, s.seed + 3);

    glm::vec3 tile = (!s.checker || ((ix + iy) & 1) == 0) ? s.color_a : s.color_b;
    tile = vary(tile, 0.12f, ix, iy, s.seed);
    // Marble veins: thin dark bands along a noise-warped diagonal.
    const float warp = tileable_fbm(x, y, 4, 5, 0.6f, s.seed + 11);
    const float vein = std::pow(1.0f - std::abs(std::sin((x + y) * glm::pi<float>() * 3.0f + warp * 9.0f)), 12.0f);
    tile *= 1.0f - s.veins * 0.6f * vein;
    tile *= 0.9f + 0.2f * grain;

    Texel t;
    t.albedo = glm::mix(s.grout_color * (0.8f + 0.4f * fine), tile, tile_mask);
    t.height = tile_mask * (1.0f + 0.02f * grain) + 0.15f * fine * (1.0f - tile_mask);
    t.roughness = glm::mix(0.9f, s.tile_roughness + 0.15f * (grain - 0.5f) + 0.3f * s.veins * vein, tile_mask);
    return t;
  });
}

TextureSet paint_bricks(int size, const BrickStyle& s) {
  const int rows = s.rows, columns = s.columns;
  const uint32_t seed = s.seed;
  return paint(size, false, true, [&](float x, float y) {
    const int row = int(y * rows);
    const float gx = x * columns + ((row & 1) ? 0.5f : 0.0f);
    const int column = int(gx) % columns;
    const float fx = fract(gx), fy = fract(y * rows);
    // Distance to the nearest joint in texture units.
    const float edge = std::min(std::min(fx, 1.0f - fx) / columns, std::min(fy, 1.0f - fy) / rows);
    const float brick_mask = smoothstep(s.joint_width, 2.0f * s.joint_width, edge);
    const float speckle = tileable_fbm(x, y, 32, 4, 0.6f, seed + 1);
    const float pits = std::pow(tileable_fbm(x, y, 96, 2, 0.5f, seed + 2), 4.0f);
    const float blotch = tileable_fbm(x, y, 6, 4, 0.5f, seed + 5);

    const size_t pick = size_t(hash01(column, row, seed) * float(s.palette.size())) % s.palette.size();
    const float texture = s.pitting > 0.0f ? (0.75f + 0.5f * speckle) * (0.85f + 0.3f * blotch) : 0.96f + 0.08f * blotch;
    const glm::vec3 brick = s.palette[pick] * texture;
    const glm::vec3 mortar = s.mortar * (0.8f + 0.4f * speckle);
    Texel t;
    t.albedo = glm::mix(mortar, brick, brick_mask);
    t.height = brick_mask * (1.0f - s.pitting * pits) + 0.15f * blotch;
    t.roughness = glm::mix(0.95f, s.brick_roughness + 0.2f * (speckle - 0.5f), brick_mask);
    t.specular = glm::mix(0.15f, 0.35f + 0.4f * blotch, brick_mask);
    return t;
  });
}

TextureSet paint_stone(int size, glm::vec3 tint, uint32_t seed) {
  // Ashlar courses: two rows of two blocks per tile, offset by half a block.
  return paint(size, false, true, [&](float x, float y) {
    const int row = int(y * 2.0f);
    const float gx = x * 2.0f + ((row & 1) ? 0.5f : 0.0f);
    const int column = int(gx) % 2;
    const float fx = fract(gx), fy = fract(y * 2.0f);
    const float edge = std::min(std::min(fx, 1.0f - fx), std::min(fy, 1.0f - fy)) * 0.5f;
    const float block_mask = smoothstep(0.002f, 0.006f, edge);
    const float grain = tileable_fbm(x, y, 16, 6, 0.55f, seed);
    const float strata = 0.5f + 0.5f * std::sin(y * glm::pi<float>() * 2.0f * 24.0f + grain * 10.0f);
    const float relief = tileable_fbm(x, y, 8, 4, 0.5f, seed + 4);
    const float pits = std::pow(tileable_fbm(x, y, 64, 2, 0.5f, seed + 9), 6.0f);

    Texel t;
    const glm::vec3 stone = vary(tint, 0.1f, column, row, seed) * (0.8f + 0.25f * grain + 0.1f * strata);
    t.albedo = glm::mix(tint * 0.55f, stone, block_mask);
    t.height = block_mask * (1.0f + 0.5f * relief - 1.5f * pits);
    t.roughness = 0.55f + 0.35f * relief + 0.1f * (1.0f - block_mask);
    t.specular = 0.3f + 0.4f * relief * block_mask;
    return t;
  });
}

TextureSet paint_wood(int size, int planks, glm::vec3 light, glm::vec3 dark, uint32_t seed) {
  // Planks run along x; growth rings are noise-warped bands along each plank.
  return paint(size, false, false, [&](float x, float y) {
    const int plank = int(y * planks);
    const float fy = fract(y * planks);
    const float shift = hash01(plank, 0, seed);  // each plank shows another part of the log
    const float seam = smoothstep(0.0f, 0.03f, std::min(fy, 1.0f - fy));
    const float warp = tileable_fbm(fract(x + shift), y, 2, 5, 0.5f, seed + plank);
    const float rings = fract(fy * 6.0f + warp * 5.0f + 13.0f * shift);
    const float ring_mask = smoothstep(0.0f, 0.25f, rings) * smoothstep(1.0f, 0.6f, rings);
    const float streaks = tileable_fbm(x, y * 8.0f - std::floor(y * 8.0f), 64, 3, 0.5f, seed + 4);

    Texel t;
    glm::vec3 wood = glm::mix(dark, light, ring_mask * (0.7f + 0.3f * streaks));
    wood = vary(wood, 0.08f, plank, 0, seed + 2);
    t.albedo = wood * (0.4f + 0.6f * seam);
    t.height = seam + 0.05f * ring_mask;
    t.roughness = 0.35f + 0.2f * (1.0f - ring_mask) + 0.3f * (1.0f - seam);
    return t;
  });
}

TextureSet paint_grille(int size, int bars) {
  return paint(size, true, false, [&](float x, float y) {
    // Vertical bars, top and bottom rails, and three rings between each pair of bars.
    // Distances are in texture units (the texture spans 1 m x 1 m).
    const float bx = fract(x * bars);
    const float bar_distance = std::abs(bx - 0.5f) / bars;
    const float rail_distance = std::min(std::abs(y - 0.06f), std::abs(y - 0.94f));
    const float cx = (bx < 0.5f ? bx : bx - 1.0f) / bars;  // offset from the gap's center line
    float ring_distance = 1.0f;
    for (float ring_y : {0.28f, 0.5f, 0.72f})  // rings just touching the bars on either side
      ring_distance = std::min(ring_distance, std::abs(std::hypot(cx, y - ring_y) - 0.46f / bars));
    const float d = std::min({bar_distance, rail_distance, ring_distance});
    const float bar_half_width = 0.008f;
    Texel t;
    t.alpha = d < bar_half_width ? 1.0f : 0.0f;
    t.albedo = glm::vec3(0.06f, 0.055f, 0.05f);
    t.height = std::max(0.0f, 1.0f - d / bar_half_width);
    t.roughness = 0.45f;
    return t;
  });
}

TextureSet paint_scales(int size, int rows, uint32_t seed) {
  const glm::vec3 teal(0.02f, 0.22f, 0.26f), gold(0.62f, 0.42f, 0.12f), rim(0.03f, 0.03f, 0.035f);
  return paint(size, false, false, [&](float x, float y) {
    // Scales sit on a staggered grid; where domes overlap the one from the lower row wins.
    const float gx = x * rows, gy = y * rows;
    float best = -1.0f, best_dome = 0.0f;
    int best_i = 0, best_j = 0;
    for (int j = int(gy) - 1; j <= int(gy) + 1; ++j) {
      for (int i = int(gx) - 1; i <= int(gx) + 1; ++i) {
        const glm::vec2 center(float(i) + 0.5f + ((j & 1) ? 0.5f : 0.0f), float(j));
        const float r = glm::length(glm::vec2(gx, gy) - center) / 0.68f;
        if (r >= 1.0f) continue;
        const float dome = std::sqrt(1.0f - r * r);
        const float order = float(j) + 0.5f * dome;  // lower rows overlap upper ones
        if (order > best) best = order, best_dome = dome, best_i = i, best_j = j;
      }
    }
    const uint32_t ci = uint32_t((best_i % rows + rows) % rows), cj = uint32_t((best_j % rows + rows) % rows);
    const float pick = hash01(ci, cj, seed);
    const float glaze = tileable_fbm(x, y, 16, 3, 0.5f, seed + 1);
    Texel t;
    const glm::vec3 color = pick < 0.8f ? vary(teal, 0.25f, ci, cj, seed + 2) : vary(gold, 0.15f, ci, cj, seed + 2);
    t.albedo = glm::mix(rim, color * (0.85f + 0.3f * glaze), smoothstep(0.0f, 0.35f, best_dome));
    t.height = best_dome + 0.03f * glaze;
    t.roughness = glm::mix(0.6f, 0.08f + 0.15f * glaze, smoothstep(0.05f, 0.5f, best_dome));
    return t;
  });
}

TextureSet paint_hull_panels(int size, glm::vec3 paint_color, glm::vec3 accent, uint32_t seed) {
  const glm::vec3 bare_metal(0.6f, 0.59f, 0.57f), stencil(0.8f, 0.79f, 0.74f);
  return paint(size, false, false, [&](float x, float y) {
    const int row = y < 0.5f ? 0 : 1;
    const float gx = fract(x - 0.25f * float(row)) * 2.0f;
    const int column = int(gx);
    const float fx = fract(gx), fy = fract(y * 2.0f);  // position in the panel
    // Distance to the nearest seam, texture units (a panel is half the tile each way).
    const float seam = 0.5f * std::min(std::min(fx, 1.0f - fx), std::min(fy, 1.0f - fy));
    const float groove = 1.0f - smoothstep(0.002f, 0.005f, seam);
    const uint32_t panel = uint32_t(row * 2 + column);
    const float pick = hash01(panel, 0, seed);

    // Rivets: a row 0.018 inside each horizontal seam, 12 per panel width.
    float rivet = 0.0f;
    for (float ry : {0.036f, 1.0f - 0.036f}) {  // in panel units (0.018 texture units)
      const float rx = (std::floor(fx * 12.0f) + 0.5f) / 12.0f;
      const float r = glm::length(glm::vec2((fx - rx) * 0.5f, (fy - ry) * 0.5f)) / 0.0055f;
      if (r < 1.0f) rivet = std::max(rivet, std::sqrt(1.0f - r * r));
    }
    // Stencilled markings on some panels: rows of 3 x 5 glyphs, each cell on or off by hash.
    float text = 0.0f;
    if (pick < 0.6f) {
      const float tx = (fx - 0.12f) / 0.03f, ty = (fy - 0.14f) / 0.05f;  // glyph units
      const int line = int(std::floor(ty));
      if (tx >= 0.0f && tx < 12.0f - 4.0f * float(line) && ty >= 0.0f && ty < 2.0f) {
        const int glyph = int(tx), cx = int(fract(tx) * 4.0f), cy = int(fract(ty) * 6.0f);
        if (cx < 3 && cy < 5) text = hash01(glyph * 8 + cx + 97 * line, cy + 16 * int(panel), seed + 3) < 0.55f ? 1.0f : 0.0f;
      }
      // A warning stripe: diagonal bands near the panel's lower edge.
      if (fy > 0.82f && fy < 0.92f && fx > 0.55f && fx < 0.9f)
        text = std::max(text, fract((fx + fy) * 12.0f) < 0.5f ? 0.85f : 0.0f);
    }
    const float peel = tileable_fbm(x, y, 96, 2, 0.5f, seed + 4);
    const float blotch = tileable_fbm(x, y, 8, 4, 0.5f, seed + 5);
    // Grime: streaks running down from the seams and rivets, heavier in the grooves.
    const float streaks = streak_noise(x, y, 192, 6, seed + 6) * tileable_fbm(x, y, 4, 3, 0.5f, seed + 7);
    const float grime = std::clamp(0.8f * groove + 0.9f * std::max(0.0f, streaks - 0.25f) + 0.25f * blotch - 0.1f, 0.0f, 1.0f);
    // Chips: noise crossing a threshold, far likelier along the seams.
    const float chip_noise = tileable_fbm(x, y, 24, 4, 0.55f, seed + 8) + 0.3f * std::exp(-seam / 0.012f);
    const float chip = smoothstep(0.76f, 0.78f, chip_noise);

    Texel t;
    glm::vec3 base = pick > 0.72f ? accent : paint_color;
    base = vary(base, 0.05f, panel, uint32_t(row), seed + 9) * (0.94f + 0.08f * blotch);
    base = glm::mix(base, stencil, text);
    base *= 1.0f - 0.55f * grime;
    t.albedo = glm::mix(base, bare_metal * (0.85f + 0.2f * peel), chip);
    t.metallic = chip;
    t.roughness = glm::mix(0.3f + 0.35f * grime, 0.35f + 0.2f * blotch, chip);
    t.height = -groove + 0.7f * rivet - 0.12f * chip + 0.06f * peel;
    return t;
  }, /*with_metallic=*/true);
}

TextureSet paint_brushed_metal(int size, glm::vec3 tint, uint32_t seed) {
  return paint(size, false, false, [&](float x, float y) {
    const float fine = streak_noise(x, y, 4, 384, seed);
    const float coarse = streak_noise(x, y, 8, 48, seed + 1);
    const float wear = tileable_fbm(x, y, 4, 4, 0.5f, seed + 2);
    const float scratch = scratches({x, y}, 40, 0.25f, 0.0025f, seed + 3);
    Texel t;
    t.albedo = tint * (0.9f + 0.07f * fine + 0.06f * coarse) * (0.96f + 0.08f * wear);
    t.roughness = 0.2f + 0.12f * coarse + 0.2f * smoothstep(0.45f, 0.75f, wear) + 0.3f * scratch;
    t.height = 0.25f * fine + 0.15f * coarse - scratch;
    return t;
  });
}

TextureSet paint_smudged(int size, glm::vec3 tint, uint32_t seed) {
  return paint(size, false, false, [&](float x, float y) {
    const float smudge = smoothstep(0.55f, 0.75f, tileable_fbm(x, y, 4, 5, 0.55f, seed));
    // Fingerprints: ridged ovals around a few hashed centres.
    float print = 0.0f;
    for (int k = 0; k < 5; ++k) {
      glm::vec2 d = glm::vec2(x, y) - glm::vec2(hash01(k, 0, seed + 1), hash01(k, 1, seed + 1));
      d -= glm::floor(d + 0.5f);
      const float r = glm::length(d * glm::vec2(1.0f, 0.75f)) / 0.045f;
      if (r < 1.0f) print = std::max(print, (1.0f - r * r) * (0.5f + 0.5f * std::sin(r * 90.0f)));
    }
    const float dust = smoothstep(0.83f, 0.86f, tileable_fbm(x, y, 128, 2, 0.5f, seed + 2));
    Texel t;
    t.albedo = tint * (0.97f + 0.03f * smudge) * (1.0f - 0.5f * dust);
    t.roughness = 0.07f + 0.22f * smudge + 0.25f * print + 0.5f * dust;
    t.height = 0.2f * print + 0.5f * dust;
    return t;
  });
}

TextureSet paint_fabric(int size, int threads, uint32_t seed) {
  return paint(size, false, false, [&](float x, float y) {
    const float gx = x * float(threads), gy = y * float(threads);
    const int ix = int(gx), iy = int(gy);
    const float fx = fract(gx), fy = fract(gy);
    // Plain weave: the warp (along y) is on top where ix + iy is even, the weft elsewhere.
    const bool warp_on_top = ((ix + iy) & 1) == 0;
    const float across = warp_on_top ? fx : fy, along = warp_on_top ? fy : fx;
    const float thread = std::sin(across * glm::pi<float>()) * (0.75f + 0.25f * std::sin(along * glm::pi<float>()));
    const float fibre = tileable_fbm(x, y, 2 * threads, 2, 0.5f, seed);
    const float slub = streak_noise(x, y, 6, threads, seed + 1);
    Texel t;
    t.albedo = glm::vec3(0.82f) * (0.8f + 0.12f * thread + 0.1f * fibre) * (0.93f + 0.1f * slub);
    t.roughness = 0.85f + 0.1f * fibre;
    t.height = thread + 0.3f * fibre;
    return t;
  });
}

TextureSet paint_rug(int size, uint32_t seed) {
  const glm::vec3 red(0.42f, 0.05f, 0.04f), navy(0.04f, 0.07f, 0.2f), cream(0.72f, 0.62f, 0.45f),
      gold(0.58f, 0.38f, 0.1f);
  return paint(size, false, false, [&](float x, float y) {
    const float edge = std::min(std::min(x, 1.0f - x), std::min(y, 1.0f - y));
    glm::vec3 color;
    if (edge < 0.02f) color = navy;                  // outer band
    else if (edge < 0.03f) color = cream;
    else if (edge < 0.09f) {                         // border: a running zig-zag
      const float along = (x < 0.09f || x > 0.91f) ? y : x;
      const float zig = std::abs(fract(along * 24.0f) - 0.5f) * 2.0f;
      color = std::abs((edge - 0.03f) / 0.06f - zig) < 0.22f ? gold : navy;
    } else if (edge < 0.1f) color = cream;
    else {                                           // field: a diamond lattice with medallions
      const float gx = (x - 0.5f) * 6.0f, gy = (y - 0.5f) * 4.0f;
      const float dx = fract(gx + 0.5f) - 0.5f, dy = fract(gy + 0.5f) - 0.5f;
      const float diamond = std::abs(dx) + std::abs(dy);
      color = diamond < 0.12f ? gold : diamond < 0.2f ? cream : diamond < 0.32f ? navy : red;
      if (std::abs(diamond - 0.42f) < 0.02f) color = cream;
    }
    const float pile = tileable_fbm(x, y, 128, 3, 0.6f, seed);
    const float wear = tileable_fbm(x, y, 6, 4, 0.5f, seed + 1);
    Texel t;
    t.albedo = color * (0.8f + 0.3f * pile) * (0.9f + 0.2f * wear);
    t.roughness = 0.95f;
    t.height = pile;
    return t;
  });
}

TextureSet paint_plaster(int size, glm::vec3 color, uint32_t seed) {
  return paint(size, false, false, [&](float x, float y) {
    const float blotch = tileable_fbm(x, y, 4, 5, 0.55f, seed);
    const float relief = tileable_fbm(x, y, 16, 5, 0.6f, seed + 1);
    Texel t;
    t.albedo = color * (0.95f + 0.08f * blotch);
    t.roughness = 0.8f + 0.15f * relief;
    t.height = relief + 0.5f * blotch;
    return t;
  });
}

MaterialDesc add_texture_set(SceneBuilder& scene, const TextureSet& set, const std::string& stem,
                             float normal_strength, glm::vec2 uv_scale, float metallic) {
  MaterialDesc desc;
  desc.name = stem;
  desc.uv_scale = uv_scale;
  desc.metallic = 1.0f;  // the texture's B channel carries the metallic value
  desc.roughness = 1.0f;
  desc.base_color_texture = scene.add_texture(encode_srgb(set.albedo), stem + "_basecolor");
  desc.normal_texture = scene.add_texture(encode_normal_map(normal_map_from_height(set.height, normal_strength)),
                                          stem + "_normal");
  const bool has_specular = !set.specular.empty();
  desc.metallic_roughness_texture = scene.add_texture(
      pack_metallic_roughness(set.roughness, metallic, has_specular ? &set.specular : nullptr,
                              set.metallic.empty() ? nullptr : &set.metallic),
      stem + "_mr");
  if (has_specular) {
    desc.use_specular = true;
    desc.specular_texture = desc.metallic_roughness_texture;
  }
  if (set.albedo.num_channels() == 4) desc.alpha_mask = true;
  return desc;
}

}  // namespace pxf::scenegen
