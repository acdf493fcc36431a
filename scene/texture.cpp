#include "scene/texture.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "image/image.h"

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
  explicit TexelReader(const Texture& t) {
    if (t.is_8bit()) {
      codes = t.texels8->data();
      rgb = t.srgb ? kTexel8Tables.srgb.data() : kTexel8Tables.linear.data();
    } else {
      floats = t.texels.data();
    }
  }
  glm::vec4 operator()(size_t i) const {
    if (floats) return floats[i];
    const unsigned char* p = codes + 4 * i;
    return glm::vec4(rgb[p[0]], rgb[p[1]], rgb[p[2]], kTexel8Tables.linear[p[3]]);
  }
};

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

}  // namespace

glm::vec4 sample_texture(const Texture& texture, glm::vec2 uv) {
  if (!texture.valid()) return glm::vec4(1.0f);
  const TexelReader read(texture);
  // Continuous texel coordinates; texel centers sit at integer + 0.5.
  float x = sanitize_coordinate(uv.x) * texture.width;
  float y = sanitize_coordinate(uv.y) * texture.height;
  if (texture.nearest) {
    const int xi = wrap_texel_index(static_cast<int>(std::floor(x)), texture.width, texture.wrap_s);
    const int yi = wrap_texel_index(static_cast<int>(std::floor(y)), texture.height, texture.wrap_t);
    return read(static_cast<size_t>(yi) * texture.width + xi);
  }
  x -= 0.5f;
  y -= 0.5f;
  float fx = std::floor(x), fy = std::floor(y);
  float tx = x - fx, ty = y - fy;
  int x0, x1, y0, y1;
  wrap_texel_pair(static_cast<int>(fx), texture.width, texture.wrap_s, &x0, &x1);
  wrap_texel_pair(static_cast<int>(fy), texture.height, texture.wrap_t, &y0, &y1);
  const size_t row0 = static_cast<size_t>(y0) * texture.width, row1 = static_cast<size_t>(y1) * texture.width;
  glm::vec4 top = glm::mix(read(row0 + x0), read(row0 + x1), tx);
  glm::vec4 bottom = glm::mix(read(row1 + x0), read(row1 + x1), tx);
  return glm::mix(top, bottom, ty);
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
