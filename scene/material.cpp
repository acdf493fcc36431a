#include "scene/material.h"

#include <algorithm>
#include <cmath>

namespace pxf {
namespace {

// A smooth or textured parameter is "delta-capable" only when it is a constant factor.
bool constant(const TextureRef& ref) { return !ref.valid(); }

// No clearcoat, or a smooth one (a delta lobe).
bool coat_is_delta_or_absent(const Material& m) {
  return !(m.clearcoat > 0.0f) || (constant(m.clearcoat_roughness_texture) && m.clearcoat_roughness < kDeltaRoughness);
}

// A sheen is never a delta lobe.
bool has_sheen(const Material& m) { return std::max(m.sheen_color.x, std::max(m.sheen_color.y, m.sheen_color.z)) > 0.0f; }

}  // namespace

bool material_is_perfect_mirror(const Material& m) {
  return constant(m.metallic_roughness_texture) && m.roughness < kDeltaRoughness && m.metallic >= 1.0f - 1e-3f &&
         coat_is_delta_or_absent(m) && !has_sheen(m);
}

// Exactly the materials whose BSDF has delta lobes only (a constant-factor mirror or glass), so
// that the specular chains, the range buffer and the LV/HV split agree about every surface.
bool material_is_perfect_specular(const Material& m) {
  if (!constant(m.metallic_roughness_texture)) return false;
  if (material_is_perfect_mirror(m)) return true;
  // Glass is smooth below the delta roughness, or at any roughness without refraction (ior 1).
  const bool smooth = m.roughness < kDeltaRoughness || std::abs(m.ior - 1.0f) < 1e-3f;
  return smooth && constant(m.transmission_texture) && m.transmission >= 1.0f - 1e-3f && m.metallic <= 1e-3f &&
         coat_is_delta_or_absent(m) && !has_sheen(m);
}

}  // namespace pxf
