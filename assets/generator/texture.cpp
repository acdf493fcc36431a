#include "texture.h"

#include <algorithm>
#include <cmath>

namespace pxf::scenegen {
namespace {

uint8_t to_byte(float v) { return uint8_t(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f)); }

float linear_to_srgb(float c) {
  c = std::clamp(c, 0.0f, 1.0f);
  return c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
}

float smootherstep(float t) { return t * t * t * (t * (t * 6.0f - 15.0f) + 10.0f); }

int positive_mod(int a, int m) { return ((a % m) + m) % m; }

}  // namespace

float wrapped(const Image& image, int x, int y) {
  return image.at(positive_mod(x, image.width), positive_mod(y, image.height), 0);
}

float hash01(uint32_t x, uint32_t y, uint32_t seed) {
  // A few rounds of a well-mixed integer hash (lowbias32-style); no library RNG, so the
  // sequence is the same on every platform and compiler.
  uint32_t h = x * 0x8da6b343u ^ y * 0xd8163841u ^ seed * 0xcb1ab31fu;
  h ^= h >> 16;
  h *= 0x7feb352du;
  h ^= h >> 15;
  h *= 0x846ca68bu;
  h ^= h >> 16;
  return float(h >> 8) * (1.0f / 16777216.0f);
}

float tileable_noise(float u, float v, int period, uint32_t seed) {
  const float fu = std::floor(u), fv = std::floor(v);
  const int x0 = positive_mod(int(fu), period), y0 = positive_mod(int(fv), period);
  const int x1 = (x0 + 1) % period, y1 = (y0 + 1) % period;
  const float tx = smootherstep(u - fu), ty = smootherstep(v - fv);
  const float a = hash01(x0, y0, seed), b = hash01(x1, y0, seed);
  const float c = hash01(x0, y1, seed), d = hash01(x1, y1, seed);
  return glm::mix(glm::mix(a, b, tx), glm::mix(c, d, tx), ty);
}

float tileable_fbm(float x, float y, int base_period, int octaves, float gain, uint32_t seed) {
  float sum = 0.0f, amplitude = 1.0f, norm = 0.0f;
  int period = base_period;
  for (int o = 0; o < octaves; ++o) {
    sum += amplitude * tileable_noise(x * period, y * period, period, seed + uint32_t(o) * 101u);
    norm += amplitude;
    amplitude *= gain;
    period *= 2;
  }
  return sum / norm;
}

Image make_field(int size, const std::function<float(float, float)>& f) {
  Image image = Image::gray(size, size);
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) image.at(x, y, 0) = f((x + 0.5f) / size, (y + 0.5f) / size);
  }
  return image;
}

Image normal_map_from_height(const Image& height, float strength) {
  Image normals = Image::rgb(height.width, height.height);
  // Central differences span two texels; slopes are per texture width.
  const float scale = strength * float(height.width) * 0.5f;
  for (int y = 0; y < height.height; ++y) {
    for (int x = 0; x < height.width; ++x) {
      const float dx = wrapped(height, x + 1, y) - wrapped(height, x - 1, y);
      // Image rows go down; +Y of the normal map points up the image.
      const float d_up = wrapped(height, x, y - 1) - wrapped(height, x, y + 1);
      glm::vec3 n = glm::normalize(glm::vec3(-dx * scale, -d_up * scale, 1.0f));
      normals.at(x, y, 0) = n.x, normals.at(x, y, 1) = n.y, normals.at(x, y, 2) = n.z;
    }
  }
  return normals;
}

ByteImage encode_srgb(const Image& linear) {
  ByteImage out{linear.width, linear.height, linear.num_channels(), {}};
  out.data.resize(linear.pixels.size());
  for (size_t i = 0; i < linear.pixels.size(); ++i) {
    const bool is_alpha = linear.num_channels() == 4 && i % 4 == 3;
    out.data[i] = to_byte(is_alpha ? linear.pixels[i] : linear_to_srgb(linear.pixels[i]));
  }
  return out;
}

ByteImage encode_linear(const Image& data) {
  ByteImage out{data.width, data.height, data.num_channels(), {}};
  out.data.resize(data.pixels.size());
  for (size_t i = 0; i < data.pixels.size(); ++i) out.data[i] = to_byte(data.pixels[i]);
  return out;
}

ByteImage encode_normal_map(const Image& normals) {
  ByteImage out{normals.width, normals.height, 3, {}};
  out.data.resize(normals.pixels.size());
  for (size_t i = 0; i < normals.pixels.size(); ++i) out.data[i] = to_byte(normals.pixels[i] * 0.5f + 0.5f);
  return out;
}

ByteImage pack_metallic_roughness(const Image& roughness, float metallic, const Image* specular,
                                  const Image* metallic_map) {
  const int channels = specular ? 4 : 3;
  ByteImage out{roughness.width, roughness.height, channels, {}};
  out.data.resize(size_t(roughness.width) * roughness.height * channels);
  for (int y = 0; y < roughness.height; ++y) {
    for (int x = 0; x < roughness.width; ++x) {
      uint8_t* texel = &out.data[(size_t(y) * roughness.width + x) * channels];
      texel[0] = 255;
      texel[1] = to_byte(roughness.at(x, y, 0));
      texel[2] = to_byte(metallic_map ? metallic_map->at(x, y, 0) : metallic);
      if (specular) texel[3] = to_byte(specular->at(x, y, 0));
    }
  }
  return out;
}

}  // namespace pxf::scenegen
