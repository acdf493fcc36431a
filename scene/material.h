// Material-level classification (factors only, a texture on metallic/roughness/transmission or
// clearcoat roughness disqualifies): a perfect mirror or a smooth dielectric, with no clearcoat or
// a smooth one, i.e. every interaction is a delta. The path tracer follows such surfaces as
// specular chains, and the range pass marks them for it; the BSDF (pathtracer/bsdf.h) makes the
// same lobes delta lobes, by the same kDeltaRoughness.
#pragma once
#include <array>

#include "scene/scene.h"

namespace pxf {

// Below this roughness a GGX lobe is a delta lobe (a mirror, smooth glass).
constexpr float kDeltaRoughness = 1e-3f;

// The texture slots the BSDF's parameters read (pathtracer/bsdf.cpp eval_material): every slot but
// the normal maps and the emission.
inline std::array<const TextureRef*, 9> bsdf_texture_slots(const Material& m) {
  return {&m.base_color_texture, &m.metallic_roughness_texture, &m.transmission_texture,
          &m.specular_texture,   &m.specular_color_texture,     &m.clearcoat_texture,
          &m.clearcoat_roughness_texture, &m.sheen_color_texture, &m.sheen_roughness_texture};
}

bool material_is_perfect_specular(const Material& material);
bool material_is_perfect_mirror(const Material& material);

}  // namespace pxf
