// Procedural texture synthesis: tileable noise, height-to-normal conversion and 8-bit encoding.
// Everything is a pure function of integer seeds, so the generated images are bit-identical
// from run to run.
#pragma once
#include <glm/glm.hpp>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace pxf::scenegen {

// A float image, top row first; `channels` floats per texel.
struct FloatImage {
  int width = 0;
  int height = 0;
  int channels = 0;
  std::vector<float> data;

  FloatImage() = default;
  FloatImage(int w, int h, int c) : width(w), height(h), channels(c), data(size_t(w) * h * c, 0.0f) {}
  float* at(int x, int y) { return &data[(size_t(y) * width + x) * channels]; }
  const float* at(int x, int y) const { return &data[(size_t(y) * width + x) * channels]; }
  // Periodic access: coordinates wrap around, matching the glTF REPEAT sampler.
  const float* wrapped(int x, int y) const;
};

// An 8-bit image ready for PNG: 3 or 4 channels.
struct ByteImage {
  int width = 0;
  int height = 0;
  int channels = 0;
  std::vector<uint8_t> data;
};

// Integer hash to [0, 1); the basis of all randomness in the generator.
float hash01(uint32_t x, uint32_t y, uint32_t seed);

// Value noise with smooth interpolation, periodic with `period` lattice cells in x and y.
// (u, v) in lattice units. Range [0, 1].
float tileableNoise(float u, float v, int period, uint32_t seed);

// Fractal sum of tileable noise: `octaves` octaves starting at `basePeriod` cells per tile,
// each doubling the frequency and multiplying the amplitude by `gain`. Range about [0, 1].
// (x, y) in [0, 1) tile coordinates.
float tileableFbm(float x, float y, int basePeriod, int octaves, float gain, uint32_t seed);

// Fills a one-channel image from f(x, y) with x, y in [0, 1) (texel centers).
FloatImage makeField(int size, const std::function<float(float, float)>& f);

// Tangent-space normal map (glTF convention: +X right, +Y up in the image, +Z out) from a
// tileable height field; `strength` scales the slopes (height units per texture width).
FloatImage normalMapFromHeight(const FloatImage& height, float strength);

// Encoders: linear RGB(A) floats to sRGB-encoded bytes (base color), or linear data to bytes.
ByteImage encodeSrgb(const FloatImage& linearRgb);
ByteImage encodeLinear(const FloatImage& data);
ByteImage encodeNormalMap(const FloatImage& normals);

// Packs roughness (G), metallic (B) and an optional specular factor (A, KHR_materials_specular)
// into one RGBA texture; R (occlusion) is left at 1. Pass an empty `specular` for RGB only.
ByteImage packMetallicRoughness(const FloatImage& roughness, float metallic,
                                const FloatImage* specular = nullptr);

}  // namespace pxf::scenegen
