// Procedural texture synthesis: tileable noise, height-to-normal conversion and 8-bit encoding.
// Everything is a pure function of integer seeds, so the generated images are bit-identical
// from run to run.
#pragma once
#include <glm/glm.hpp>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "image/image.h"

namespace pxf::scenegen {

// Float images are pxf::Image ("Y", "R,G,B" or "R,G,B,A"), top row first.
using pxf::Image;

// Channel 0 of `image` at (x, y) with periodic coordinates, matching the glTF REPEAT sampler.
float wrapped(const Image& image, int x, int y);

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
float tileable_noise(float u, float v, int period, uint32_t seed);

// Fractal sum of tileable noise: `octaves` octaves starting at `base_period` cells per tile,
// each doubling the frequency and multiplying the amplitude by `gain`. Range about [0, 1].
// (x, y) in [0, 1) tile coordinates.
float tileable_fbm(float x, float y, int base_period, int octaves, float gain, uint32_t seed);

// Fills a one-channel image from f(x, y) with x, y in [0, 1) (texel centers).
Image make_field(int size, const std::function<float(float, float)>& f);

// Tangent-space normal map (glTF convention: +X right, +Y up in the image, +Z out) from a
// tileable height field; `strength` scales the slopes (height units per texture width).
Image normal_map_from_height(const Image& height, float strength);

// Encoders: linear RGB(A) floats to sRGB-encoded bytes (base color), or linear data to bytes.
ByteImage encode_srgb(const Image& linear_rgb);
ByteImage encode_linear(const Image& data);
ByteImage encode_normal_map(const Image& normals);

// Packs roughness (G), metallic (B) and an optional specular factor (A, KHR_materials_specular)
// into one RGBA texture; R (occlusion) is left at 1. Pass an empty `specular` for RGB only.
// A `metallic_map` (1 channel) replaces the constant `metallic` texel by texel.
ByteImage pack_metallic_roughness(const Image& roughness, float metallic,
                                  const Image* specular = nullptr, const Image* metallic_map = nullptr);

}  // namespace pxf::scenegen
