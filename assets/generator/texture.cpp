#include "texture.h"

#include <algorithm>
#include <cmath>

namespace pxf::scenegen {
namespace {

uint8_t toByte(float v) { return uint8_t(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f)); }

float linearToSrgb(float c) {
  c = std::clamp(c, 0.0f, 1.0f);
  return c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
}

float smootherstep(float t) { return t * t * t * (t * (t * 6.0f - 15.0f) + 10.0f); }

int positiveMod(int a, int m) { return ((a % m) + m) % m; }

}  // namespace

const float* FloatImage::wrapped(int x, int y) const {
  return at(positiveMod(x, width), positiveMod(y, height));
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

float tileableNoise(float u, float v, int period, uint32_t seed) {
  const float fu = std::floor(u), fv = std::floor(v);
  const int x0 = positiveMod(int(fu), period), y0 = positiveMod(int(fv), period);
  const int x1 = (x0 + 1) % period, y1 = (y0 + 1) % period;
  const float tx = smootherstep(u - fu), ty = smootherstep(v - fv);
  const float a = hash01(x0, y0, seed), b = hash01(x1, y0, seed);
  const float c = hash01(x0, y1, seed), d = hash01(x1, y1, seed);
  return glm::mix(glm::mix(a, b, tx), glm::mix(c, d, tx), ty);
}

float tileableFbm(float x, float y, int basePeriod, int octaves, float gain, uint32_t seed) {
  float sum = 0.0f, amplitude = 1.0f, norm = 0.0f;
  int period = basePeriod;
  for (int o = 0; o < octaves; ++o) {
    sum += amplitude * tileableNoise(x * period, y * period, period, seed + uint32_t(o) * 101u);
    norm += amplitude;
    amplitude *= gain;
    period *= 2;
  }
  return sum / norm;
}

FloatImage makeField(int size, const std::function<float(float, float)>& f) {
  FloatImage image(size, size, 1);
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) image.at(x, y)[0] = f((x + 0.5f) / size, (y + 0.5f) / size);
  }
  return image;
}

FloatImage normalMapFromHeight(const FloatImage& height, float strength) {
  FloatImage normals(height.width, height.height, 3);
  // Central differences span two texels; slopes are per texture width.
  const float scale = strength * float(height.width) * 0.5f;
  for (int y = 0; y < height.height; ++y) {
    for (int x = 0; x < height.width; ++x) {
      const float dx = height.wrapped(x + 1, y)[0] - height.wrapped(x - 1, y)[0];
      // Image rows go down; +Y of the normal map points up the image.
      const float dUp = height.wrapped(x, y - 1)[0] - height.wrapped(x, y + 1)[0];
      glm::vec3 n = glm::normalize(glm::vec3(-dx * scale, -dUp * scale, 1.0f));
      float* out = normals.at(x, y);
      out[0] = n.x, out[1] = n.y, out[2] = n.z;
    }
  }
  return normals;
}

ByteImage encodeSrgb(const FloatImage& linear) {
  ByteImage out{linear.width, linear.height, linear.channels, {}};
  out.data.resize(linear.data.size());
  for (size_t i = 0; i < linear.data.size(); ++i) {
    const bool isAlpha = linear.channels == 4 && i % 4 == 3;
    out.data[i] = toByte(isAlpha ? linear.data[i] : linearToSrgb(linear.data[i]));
  }
  return out;
}

ByteImage encodeLinear(const FloatImage& data) {
  ByteImage out{data.width, data.height, data.channels, {}};
  out.data.resize(data.data.size());
  for (size_t i = 0; i < data.data.size(); ++i) out.data[i] = toByte(data.data[i]);
  return out;
}

ByteImage encodeNormalMap(const FloatImage& normals) {
  ByteImage out{normals.width, normals.height, 3, {}};
  out.data.resize(normals.data.size());
  for (size_t i = 0; i < normals.data.size(); ++i) out.data[i] = toByte(normals.data[i] * 0.5f + 0.5f);
  return out;
}

ByteImage packMetallicRoughness(const FloatImage& roughness, float metallic, const FloatImage* specular) {
  const int channels = specular ? 4 : 3;
  ByteImage out{roughness.width, roughness.height, channels, {}};
  out.data.resize(size_t(roughness.width) * roughness.height * channels);
  for (int y = 0; y < roughness.height; ++y) {
    for (int x = 0; x < roughness.width; ++x) {
      uint8_t* texel = &out.data[(size_t(y) * roughness.width + x) * channels];
      texel[0] = 255;
      texel[1] = toByte(roughness.at(x, y)[0]);
      texel[2] = toByte(metallic);
      if (specular) texel[3] = toByte(specular->at(x, y)[0]);
    }
  }
  return out;
}

}  // namespace pxf::scenegen
