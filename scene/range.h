// What the path tracer and the raster range pass agree on for the range buffer (docs/method.md
// section 1.2): the range colors of a surface and of the environment, and what a camera ray's
// perfectly specular chain reaches, which the path tracer traces for the range pass.
#pragma once
#include <glm/glm.hpp>
#include "shaders/range_formulas.h"

namespace pxf {

// The range-buffer colors of a surface and of the environment (docs/method.md section 1.2), which
// the raster pass's shaders compute from the same source (shaders/range_formulas.h).
using shared::range_environment_color;
using shared::range_shading;

// Result of following a perfectly specular chain from the camera (docs/method.md section 1.2).
struct SpecularChainHit {
  // hit: albedo x chain tint x range_shading at the first non-specular hit; escaped:
  // range_environment_color(chain tint x environment radiance), black without an environment.
  glm::vec3 range_color{0.0f};
  float distance = 0.0f;  // total distance along the chain, scene units (hit only)
  bool hit = false;       // false: the chain escaped (the range pass uses the background distance)
  // The surface buffer's texel at the chain's end (hit only): the shading normal there, flipped
  // toward the chain's last ray for double-sided materials, and the roughness; an escaped chain
  // leaves the normal 0 (unknown), as the environment's pixels have.
  glm::vec3 normal{0.0f};
  float roughness = 0.0f;
};

}  // namespace pxf
