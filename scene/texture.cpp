#include "scene/texture.h"

#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <map>
#include <memory>
#include <utility>

#include "core/parallel.h"
#include "image/image.h"
#include "scene/material.h"

namespace pxf {

int wrap_texel_index(int i, int size, Wrap wrap) {
  if (size <= 1) return 0;
  switch (wrap) {
    case Wrap::ClampToEdge:
      return i < 0 ? 0 : (i >= size ? size - 1 : i);
    case Wrap::MirroredRepeat: {
      int period = 2 * size;
      int m = i % period;
      if (m < 0) m += period;
      return m < size ? m : period - 1 - m;
    }
    case Wrap::Repeat:
    default: {
      int m = i % size;
      return m < 0 ? m + size : m;
    }
  }
}

namespace {

struct Texel8Tables {
  std::array<float, 256> srgb, linear;
  Texel8Tables() {
    for (int k = 0; k < 256; ++k) {
      linear[k] = k / 255.0f;
      srgb[k] = linear_from_srgb(k / 255.0f);
    }
  }
};
// Built at static initialization, not on first use: a function-local static is a guarded load
// at each of the four texels of every bilinear lookup. Nothing samples a texture before main().
const Texel8Tables kTexel8Tables;

// Reads texels as linear RGBA from either storage. A bilinear look-up reads four, so the storage
// kind and the decode table are chosen once, when the reader is made, not per texel.
struct TexelReader {
  const glm::vec4* floats = nullptr;
  const unsigned char* codes = nullptr;
  const float* rgb = nullptr;
  TexelReader(const glm::vec4* float_texels, const unsigned char* code_texels, bool srgb) {
    if (code_texels) {
      codes = code_texels;
      rgb = srgb ? kTexel8Tables.srgb.data() : kTexel8Tables.linear.data();
    } else {
      floats = float_texels;
    }
  }
  explicit TexelReader(const Texture& t)
      : TexelReader(t.texels.data(), t.is_8bit() ? t.texels8->data() : nullptr, t.srgb) {}
  glm::vec4 operator()(size_t i) const {
    if (floats) return floats[i];
    const unsigned char* p = codes + 4 * i;
    return glm::vec4(rgb[p[0]], rgb[p[1]], rgb[p[2]], kTexel8Tables.linear[p[3]]);
  }
};

// One level of a texture as the bilinear look-up reads it.
struct TexelGrid {
  int width, height;
  TexelReader read;
};

TexelGrid level_grid(const Texture& t, int level) {
  if (level == 0) return {t.width, t.height, TexelReader(t)};
  const TextureLevel& l = (*t.mips)[static_cast<size_t>(level) - 1];
  return {l.width, l.height, TexelReader(l.texels.data(), l.texels8.empty() ? nullptr : l.texels8.data(), t.srgb)};
}

}  // namespace

float texel8_to_linear(unsigned char k, bool srgb) {
  return srgb ? kTexel8Tables.srgb[k] : kTexel8Tables.linear[k];
}

glm::vec4 Texture::texel(size_t i) const { return TexelReader(*this)(i); }

namespace {

// Keeps huge or non-finite coordinates from overflowing the integer texel arithmetic.
float sanitize_coordinate(float x) {
  if (!std::isfinite(x)) return 0.0f;
  const float limit = 1.0e6f;
  if (x > limit || x < -limit) x = std::fmod(x, limit);
  return x;
}

// wrap_texel_index(i) and wrap_texel_index(i + 1), with no division when i is already inside
// [0, size) under Repeat (the common case: uvs in [0, 1)).
void wrap_texel_pair(int i, int size, Wrap wrap, int* first, int* second) {
  if (wrap == Wrap::Repeat && size > 1) {
    const int m = (i >= 0 && i < size) ? i : wrap_texel_index(i, size, wrap);
    *first = m;
    *second = m + 1 == size ? 0 : m + 1;
    return;
  }
  *first = wrap_texel_index(i, size, wrap);
  *second = wrap_texel_index(i + 1, size, wrap);
}

// The bilinear (or nearest) look-up of one level, under the texture's wrap modes.
glm::vec4 sample_grid(const Texture& texture, const TexelGrid& grid, glm::vec2 uv) {
  const TexelReader& read = grid.read;
  // Continuous texel coordinates; texel centers sit at integer + 0.5.
  float x = sanitize_coordinate(uv.x) * grid.width;
  float y = sanitize_coordinate(uv.y) * grid.height;
  if (texture.nearest) {
    const int xi = wrap_texel_index(static_cast<int>(std::floor(x)), grid.width, texture.wrap_s);
    const int yi = wrap_texel_index(static_cast<int>(std::floor(y)), grid.height, texture.wrap_t);
    return read(static_cast<size_t>(yi) * grid.width + xi);
  }
  x -= 0.5f;
  y -= 0.5f;
  float fx = std::floor(x), fy = std::floor(y);
  float tx = x - fx, ty = y - fy;
  int x0, x1, y0, y1;
  wrap_texel_pair(static_cast<int>(fx), grid.width, texture.wrap_s, &x0, &x1);
  wrap_texel_pair(static_cast<int>(fy), grid.height, texture.wrap_t, &y0, &y1);
  const size_t row0 = static_cast<size_t>(y0) * grid.width, row1 = static_cast<size_t>(y1) * grid.width;
  glm::vec4 top = glm::mix(read(row0 + x0), read(row0 + x1), tx);
  glm::vec4 bottom = glm::mix(read(row1 + x0), read(row1 + x1), tx);
  return glm::mix(top, bottom, ty);
}

}  // namespace

glm::vec4 sample_texture(const Texture& texture, glm::vec2 uv) {
  if (!texture.valid()) return glm::vec4(1.0f);
  return sample_grid(texture, level_grid(texture, 0), uv);
}

int texture_level(const Texture& texture, float uv_width) {
  if (!texture.mips || !(uv_width > 0.0f)) return 0;
  // Texels of level 0 across the footprint; level k's texels are 2^k of them wide.
  const float texels = uv_width * static_cast<float>(std::max(texture.width, texture.height));
  if (!(texels >= 2.0f)) return 0;
  const int level = std::isfinite(texels) ? std::ilogb(texels) : INT_MAX;
  return std::min(level, static_cast<int>(texture.mips->size()));
}

glm::vec4 sample_texture(const Texture& texture, glm::vec2 uv, float uv_width) {
  if (!texture.valid()) return glm::vec4(1.0f);
  return sample_grid(texture, level_grid(texture, texture_level(texture, uv_width)), uv);
}

namespace {

// Level k + 1 of a chain from level k, whose texel i is fine(i) (linear RGBA): each texel the mean
// of the 2x2 texels it covers (an odd last row or column is averaged with itself).
template <typename Fine>
std::vector<glm::vec4> half_level(const Fine& fine, int width, int height, int* half_width, int* half_height) {
  const int w = std::max(1, width / 2), h = std::max(1, height / 2);
  std::vector<glm::vec4> out(static_cast<size_t>(w) * h);
  for (int y = 0; y < h; ++y) {
    const size_t row0 = static_cast<size_t>(std::min(2 * y, height - 1)) * width;
    const size_t row1 = static_cast<size_t>(std::min(2 * y + 1, height - 1)) * width;
    for (int x = 0; x < w; ++x) {
      const int x0 = std::min(2 * x, width - 1), x1 = std::min(2 * x + 1, width - 1);
      out[static_cast<size_t>(y) * w + x] =
          0.25f * (fine(row0 + x0) + fine(row0 + x1) + fine(row1 + x0) + fine(row1 + x1));
    }
  }
  *half_width = w;
  *half_height = h;
  return out;
}

// The code whose decoded value (in `decoded`, ascending) is nearest to v.
unsigned char nearest_code(const std::array<float, 256>& decoded, float v) {
  const auto above = std::lower_bound(decoded.begin(), decoded.end(), v);
  if (above == decoded.begin()) return 0;
  if (above == decoded.end()) return 255;
  const auto below = above - 1;
  return static_cast<unsigned char>((v - *below < *above - v ? below : above) - decoded.begin());  // ties up
}

// Linear RGBA back to the 8-bit codes of a texture stored as `srgb` (alpha always linear): the
// code that decodes nearest to each value, so the level's mean light is kept.
std::vector<unsigned char> encode_level(const std::vector<glm::vec4>& texels, bool srgb) {
  const std::array<float, 256>& rgb = srgb ? kTexel8Tables.srgb : kTexel8Tables.linear;
  std::vector<unsigned char> codes(4 * texels.size());
  for (size_t i = 0; i < texels.size(); ++i) {
    for (int c = 0; c < 3; ++c) codes[4 * i + c] = nearest_code(rgb, texels[i][c]);
    codes[4 * i + 3] = nearest_code(kTexel8Tables.linear, texels[i].w);
  }
  return codes;
}

// Level 1 is averaged from level 0's texels as lookups decode them; each level after from the
// float level before it, so 8-bit levels are rounded once each, not at every halving.
std::shared_ptr<const std::vector<TextureLevel>> mip_chain(const Texture& texture) {
  auto chain = std::make_shared<std::vector<TextureLevel>>();
  const TexelReader level0(texture);
  std::vector<glm::vec4> level;
  int width = texture.width, height = texture.height;
  while (width > 1 || height > 1) {
    if (chain->empty())
      level = half_level(level0, width, height, &width, &height);
    else
      level = half_level([&](size_t i) { return level[i]; }, width, height, &width, &height);
    TextureLevel out;
    out.width = width;
    out.height = height;
    if (texture.is_8bit())
      out.texels8 = encode_level(level, texture.srgb);
    else
      out.texels = level;
    chain->push_back(std::move(out));
  }
  return chain;
}

}  // namespace

void build_texture_mips(std::vector<Texture>& textures, const std::vector<bool>* wanted) {
  // Textures that share their 8-bit codes and encoding share one chain.
  std::map<std::pair<const void*, bool>, size_t> first_user;
  std::vector<size_t> owners;
  for (size_t t = 0; t < textures.size(); ++t) {
    const Texture& texture = textures[t];
    if (!texture.valid() || texture.mips || (wanted && !(t < wanted->size() && (*wanted)[t]))) continue;
    if (texture.is_8bit() && !first_user.emplace(std::make_pair(texture.texels8.get(), texture.srgb), t).second) continue;
    owners.push_back(t);
  }
  parallel_for(owners.size(), [&](size_t k) { textures[owners[k]].mips = mip_chain(textures[owners[k]]); });
  for (Texture& texture : textures) {
    if (!texture.valid() || texture.mips || !texture.is_8bit()) continue;
    const auto owner = first_user.find(std::make_pair(texture.texels8.get(), texture.srgb));
    if (owner != first_user.end()) texture.mips = textures[owner->second].mips;
  }
}

std::vector<bool> textures_read_with_footprints(const Scene& scene) {
  std::vector<bool> wanted(scene.textures.size(), false);
  for (const Material& m : scene.materials)
    for (const TextureRef* ref : bsdf_texture_slots(m))
      if (ref->valid() && ref->texture < static_cast<int>(wanted.size())) wanted[ref->texture] = true;
  return wanted;
}

glm::vec2 texture_uv(const TextureRef& ref, glm::vec2 uv0, glm::vec2 uv1) {
  glm::vec2 uv = ref.texcoord == 1 ? uv1 : uv0;
  glm::vec3 t = ref.transform * glm::vec3(uv, 1.0f);
  return glm::vec2(t);
}

glm::mat3 texture_transform_matrix(glm::vec2 offset, float rotation, glm::vec2 scale) {
  // glm is column-major: mat3(col0, col1, col2).
  glm::mat3 translation(1, 0, 0, 0, 1, 0, offset.x, offset.y, 1);
  float c = std::cos(rotation), s = std::sin(rotation);
  // The extension's matrix: [c s 0; -s c 0; 0 0 1] in row-major notation.
  glm::mat3 rotate(c, -s, 0, s, c, 0, 0, 0, 1);
  glm::mat3 scaling(scale.x, 0, 0, 0, scale.y, 0, 0, 0, 1);
  return translation * rotate * scaling;
}

namespace {
constexpr float kPi = 3.14159265358979323846f;
constexpr float kInvPi = 0.31830988618379067154f;
}  // namespace

glm::vec2 equirect_uv(glm::vec3 d) {
  float u = 0.5f + std::atan2(d.x, -d.z) * (0.5f * kInvPi);
  float v = std::acos(std::min(std::max(d.y, -1.0f), 1.0f)) * kInvPi;
  return glm::vec2(u - std::floor(u), v);
}

glm::vec3 equirect_direction(glm::vec2 uv) {
  float theta = uv.y * kPi, phi = (uv.x - 0.5f) * 2.0f * kPi;
  float s = std::sin(theta);
  return glm::vec3(s * std::sin(phi), std::cos(theta), -s * std::cos(phi));
}

}  // namespace pxf
