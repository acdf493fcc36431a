// Directional albedo of the single-scattering GGX lobe (height-correlated Smith G2), tabulated over
// (cos theta_o, perceptual roughness) for the energy compensation of the rough lobes (Turquin 2019,
// docs/materials.md). The table (ggx_albedo_table.inc) is written by tools/make_albedo_table.cpp ggx
// from ggx_albedo_quadrature(); regenerate it with the command in docs/materials.md.
#pragma once

namespace pxf {

// The single-scattering lobe's albedo with Schlick Fresnel F = f0 + (f90 - f0)(1 - cos_oh)^5 is
// f0 * (total - schlick) + f90 * schlick.
struct GgxAlbedo {
  float total = 1.0f;    // integral of D G2 / (4 cos_o) over the hemisphere of wi (F = 1)
  float schlick = 0.0f;  // the same with F = (1 - wo.h)^5
};

constexpr int kGgxAlbedoSize = 32;  // table points along cos theta_o and along roughness

// The table's grid: point j along the cosine is at cos theta_o = (j / (kGgxAlbedoSize - 1))^2 (the
// albedo rises steeply to 1 at grazing, and this spacing puts a fifth of the points below 0.04),
// kept above kGgxAlbedoMinCos (the integrand is undefined at 0); point i along roughness is at
// roughness i / (kGgxAlbedoSize - 1), alpha = max(roughness^2, kMinAlpha).
constexpr float kGgxAlbedoMinCos = 1e-4f;

// Point j of n along the cosine (squared spacing) and point i of n along roughness (alpha = max(r^2,
// min_alpha)): the grids of this table and of the glass table (glass_albedo.h), for their tests.
inline float albedo_grid_cos(int j, int n) {
  const float s = static_cast<float>(j) / static_cast<float>(n - 1);
  return s * s;
}
inline float albedo_grid_alpha(int i, int n, float min_alpha) {
  const float r = static_cast<float>(i) / static_cast<float>(n - 1);
  return r * r > min_alpha ? r * r : min_alpha;
}

// Deterministic quadrature: a midpoint grid of n x n points over the visible-normal sampling's unit
// square, each weighted by G2 / G1(wo) (the exact estimator of VNDF sampling). The generator's.
GgxAlbedo ggx_albedo_quadrature(float cos_o, float alpha, int n);

// Bilinear lookup in the generated table; alpha as the BSDF uses it (>= kMinAlpha).
GgxAlbedo ggx_albedo(float cos_o, float alpha);

// The generated table (row-major: roughness index, then cosine index), for its tests.
const GgxAlbedo& ggx_albedo_table_entry(int roughness_index, int cos_index);

}  // namespace pxf
