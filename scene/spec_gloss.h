// KHR_materials_pbrSpecularGlossiness → metallic-roughness, the conversion the common glTF tools
// use (Babylon.js, three.js, the Khronos sample viewer's converter): glossiness becomes roughness
// 1 - g, and metallic is solved from the brightness of the specular (F0) and diffuse colors
// against a dielectric F0 of 0.04, so a dark specular gives a dielectric whose base color is the
// diffuse color, and a bright specular over a black diffuse gives a metal whose base color is the
// specular color.
#pragma once
#include <glm/glm.hpp>
#include "scene/scene.h"

namespace pxf {

struct MetalRough {
  glm::vec4 base_color{1.0f};  // alpha: the diffuse alpha
  float metallic = 0.0f;
  float roughness = 1.0f;
};

// Inputs are linear and already multiplied by their factors; clamped to [0, 1].
MetalRough metal_rough_from_spec_gloss(glm::vec4 diffuse, glm::vec3 specular, float glossiness);

// The extension's factors with the texture values they multiply (linear RGBA, vec4(1) when a
// texture is absent).
struct SpecGlossFactors {
  glm::vec4 diffuse{1.0f};
  glm::vec3 specular{1.0f};
  float glossiness = 1.0f;
};

// Bakes the conversion per texel into a base color texture (8-bit sRGB, RGBA) and a
// metallic-roughness texture (8-bit linear, G = roughness, B = metallic), at width x height,
// sampling `diffuse` and `spec_gloss` (RGB specular, A glossiness; either may be null) bilinearly
// at each output texel's center in [0, 1]² UV. Both inputs must be read through the same UV
// mapping for the result to be exact. The outputs take `sampler`'s wrap and filter settings.
struct BakedSpecGloss {
  Texture base_color;
  Texture metallic_roughness;
};
BakedSpecGloss bake_spec_gloss(const Texture* diffuse, const Texture* spec_gloss, const SpecGlossFactors& factors,
                               int width, int height, const Texture& sampler);

}  // namespace pxf
