#include "pathtracer/texture.h"

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
const Texel8Tables& texel8_tables() {
  static const Texel8Tables tables;
  return tables;
}

}  // namespace

float texel8_to_linear(unsigned char k, bool srgb) {
  return srgb ? texel8_tables().srgb[k] : texel8_tables().linear[k];
}

glm::vec4 Texture::texel(size_t i) const {
  if (!is_8bit()) return texels[i];
  const Texel8Tables& tables = texel8_tables();
  const float* rgb = srgb ? tables.srgb.data() : tables.linear.data();
  const unsigned char* p = texels8->data() + 4 * i;
  return glm::vec4(rgb[p[0]], rgb[p[1]], rgb[p[2]], tables.linear[p[3]]);
}

namespace {

// Keeps huge or non-finite coordinates from overflowing the integer texel arithmetic.
float sanitize_coordinate(float x) {
  if (!std::isfinite(x)) return 0.0f;
  const float limit = 1.0e6f;
  if (x > limit || x < -limit) x = std::fmod(x, limit);
  return x;
}

glm::vec4 texel(const Texture& t, int x, int y) {
  x = wrap_texel_index(x, t.width, t.wrap_s);
  y = wrap_texel_index(y, t.height, t.wrap_t);
  return t.texel(static_cast<size_t>(y) * t.width + x);
}

}  // namespace

glm::vec4 sample_texture(const Texture& texture, glm::vec2 uv) {
  if (!texture.valid()) return glm::vec4(1.0f);
  // Continuous texel coordinates; texel centers sit at integer + 0.5.
  float x = sanitize_coordinate(uv.x) * texture.width;
  float y = sanitize_coordinate(uv.y) * texture.height;
  if (texture.nearest) {
    return texel(texture, static_cast<int>(std::floor(x)), static_cast<int>(std::floor(y)));
  }
  x -= 0.5f;
  y -= 0.5f;
  float fx = std::floor(x), fy = std::floor(y);
  int x0 = static_cast<int>(fx), y0 = static_cast<int>(fy);
  float tx = x - fx, ty = y - fy;
  glm::vec4 top = glm::mix(texel(texture, x0, y0), texel(texture, x0 + 1, y0), tx);
  glm::vec4 bottom = glm::mix(texel(texture, x0, y0 + 1), texel(texture, x0 + 1, y0 + 1), tx);
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

}  // namespace pxf
