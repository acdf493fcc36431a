// Texture sampling shared by the integrator and the loader: wrap modes, bilinear or nearest
// filtering, KHR_texture_transform. Lookups return linear values: 8-bit sRGB texels are decoded
// through a 256-entry table.
#pragma once
#include <cmath>
#include <vector>

#include <glm/glm.hpp>
#include "scene/scene.h"

namespace pxf {

// Samples `texture` at `uv` (glTF convention: (0,0) = top-left texel corner, v grows downwards,
// which matches Texture's top-row-first storage). Honors wrap_s/wrap_t and `nearest`.
// Returns vec4(1) for an empty texture; never returns NaN for finite input.
glm::vec4 sample_texture(const Texture& texture, glm::vec2 uv);

// The same look-up on the mip level (texture.mips) whose texels are at most `uv_width` wide in uv
// units, the footprint of the ray that reads it: level 0 for a width of 0 (or without mips).
// The path tracer reads deep vertices this way (docs/sampling.md, "Texture footprints").
glm::vec4 sample_texture(const Texture& texture, glm::vec2 uv, float uv_width);
int texture_level(const Texture& texture, float uv_width);

// Fills `mips` of every valid texture that has none (of those with wanted[t], when given): levels
// down to 1x1, each the 2x2 box mean of the one before in linear light, 8-bit textures re-encoded
// to the codes nearest those means.
void build_texture_mips(std::vector<Texture>& textures, const std::vector<bool>* wanted = nullptr);

// The textures the path tracer reads with a footprint: those of bsdf_texture_slots (the normal
// maps and the emission it reads at level 0: pathtracer/embree_scene.cpp, bsdf.cpp).
std::vector<bool> textures_read_with_footprints(const Scene& scene);

// The coordinates a texture reference reads: picks uv0 or uv1 by ref.texcoord and applies
// ref.transform (KHR_texture_transform) to (u, v, 1).
glm::vec2 texture_uv(const TextureRef& ref, glm::vec2 uv0, glm::vec2 uv1);

// sample_texture(scene.textures[ref.texture], texture_uv(ref, uv0, uv1)), or `fallback` when the
// reference is unset or out of range. Inline: most material slots have no texture, and this is
// called for each of them at every path vertex. `uv_width`: the footprint in the mesh's uv units
// (0: level 0), scaled by the reference's transform.
inline glm::vec4 eval_texture(const Scene& scene, const TextureRef& ref, glm::vec2 uv0, glm::vec2 uv1,
                              glm::vec4 fallback = glm::vec4(1.0f), float uv_width = 0.0f) {
  if (!ref.valid() || ref.texture >= static_cast<int>(scene.textures.size())) return fallback;
  const Texture& texture = scene.textures[ref.texture];
  if (uv_width > 0.0f) {
    const float scale = std::sqrt(std::abs(ref.transform[0][0] * ref.transform[1][1] - ref.transform[0][1] * ref.transform[1][0]));
    return sample_texture(texture, texture_uv(ref, uv0, uv1), uv_width * scale);
  }
  return sample_texture(texture, texture_uv(ref, uv0, uv1));
}

// The 3x3 matrix of KHR_texture_transform: T(offset) * R(rotation) * S(scale), as the extension
// defines it (rotation counter-clockwise in UV space, radians).
glm::mat3 texture_transform_matrix(glm::vec2 offset, float rotation, glm::vec2 scale);

// The linear value of 8-bit code k: linear_from_srgb(k / 255) when `srgb`, else k / 255 (exactly
// the float the loader used to store).
float texel8_to_linear(unsigned char k, bool srgb);

// Integer texel index for coordinate `i` (may be outside [0, size)) under `wrap`.
int wrap_texel_index(int i, int size, Wrap wrap);

// Direction <-> equirect coordinates (Environment's convention, scene.h).
glm::vec2 equirect_uv(glm::vec3 direction);
glm::vec3 equirect_direction(glm::vec2 uv);

}  // namespace pxf
