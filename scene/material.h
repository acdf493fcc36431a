// Material-level classification (factors only, a texture on metallic/roughness/transmission or
// clearcoat roughness disqualifies): a perfect mirror or a smooth dielectric, with no clearcoat or
// a smooth one, i.e. every interaction is a delta. The path tracer follows such surfaces as
// specular chains, and the range pass marks them for it; the BSDF (pathtracer/bsdf.h) makes the
// same lobes delta lobes, by the same kDeltaRoughness.
#pragma once
#include "scene/scene.h"

namespace pxf {

// Below this roughness a GGX lobe is a delta lobe (a mirror, smooth glass).
constexpr float kDeltaRoughness = 1e-3f;

bool material_is_perfect_specular(const Material& material);
bool material_is_perfect_mirror(const Material& material);

}  // namespace pxf
