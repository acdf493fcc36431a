// Directional albedo of the single-scattering rough dielectric (the rough glass lobe of bsdf.cpp:
// Walter et al. 2007 with GGX, exact Fresnel, height-correlated Smith G2), tabulated over
// (cos theta_o, roughness, ior) on both sides of the interface, for the lobe's energy compensation
// (Kulla and Conty 2017, docs/materials.md). The table (glass_albedo_table.inc) is written by
// tools/make_albedo_table.cpp glass from glass_albedo_quadrature(); regenerate it with the command in
// docs/materials.md.
#pragma once

namespace pxf {

// The energy the lobe sends on of a unit of light arriving against wo: reflected plus transmitted,
// the transmitted radiance's 1/eta^2 undone (what a white interface in a uniform surrounding
// returns). Single scattering keeps total < 1; the rest scattered more than once between microfacets.
struct GlassAlbedo {
  float total = 1.0f;
  float reflected = 0.0f;  // the share of `total` reflected (the rest is transmitted)
};

// The table's grid. Side 0: wo outside (eta = ior); side 1: wo inside (eta = 1 / ior).
// Along the cosine, point j at cos theta_o = (j / (kGlassAlbedoCosSize - 1))^2 (as ggx_albedo.h's:
// the albedo changes fastest near grazing), the first computed at kGgxAlbedoMinCos.
// Along roughness, point i at roughness i / (kGlassAlbedoRoughnessSize - 1), alpha = max(roughness^2, kMinAlpha).
// Along the ior, point k at ior (1 + x) / (1 - x), x = k kGlassAlbedoIorStep: up to 3.44, 1.5 (glTF's
// default) at k = 4; but the first at x = kGlassAlbedoFirstX, ior 1.02, not at ior 1, where the
// refraction passes straight through and the albedo is not the limit of the albedos above. An ior
// outside [1.02, 3.44] is looked up at the nearest end.
constexpr int kGlassAlbedoCosSize = 16;
constexpr int kGlassAlbedoRoughnessSize = 12;
constexpr int kGlassAlbedoIorSize = 12;
constexpr float kGlassAlbedoIorStep = 0.05f;
constexpr float kGlassAlbedoFirstX = 0.01f;

float glass_table_ior(int ior_index);

// Deterministic quadrature: a midpoint grid of n x n points over the visible-normal sampling's unit
// square, each reflecting with weight F G2 / G1(wo) and refracting with (1 - F) G2 / G1(wo) (the
// exact estimator of the lobe's sampling). eta = eta_t / eta_i. The generator's.
GlassAlbedo glass_albedo_quadrature(float cos_o, float alpha, float eta, int n);

// The generated table, for its tests.
const GlassAlbedo& glass_albedo_table_entry(int side, int ior_index, int roughness_index, int cos_index);

// The table at one (alpha, ior), blended bilinearly from its four nearest (ior, roughness) rows, and
// what the compensation lobe needs of it: E (linear along sqrt(cos) between the grid points), its
// cosine-weighted average, the smooth interface's average Fresnel, and sampling in proportion to
// the loss 1 - E. Side 0 is the outside (eta = ior), side 1 the inside.
class GlassAlbedoLookup {
 public:
  GlassAlbedoLookup() = default;
  GlassAlbedoLookup(float alpha, float ior);
  GlassAlbedo at(int side, float cos_theta) const;
  // E_avg = 2 integral of E(mu) mu dmu over [0, 1], exact for the interpolated table.
  float average(int side) const;
  // F_avg = 2 integral of F(mu) mu dmu of the smooth interface (total internal reflection included).
  float fresnel_average(int side) const;
  // cos theta drawn with density (1 - E(mu)) 2 mu / (1 - E_avg) in mu: in proportion to the light
  // single scattering loses, arriving from that direction. -1 where nothing is lost.
  float sample_loss_cos(int side, float u) const;

 private:
  int ior_index_ = 0, roughness_index_ = 0;  // the lower corner of the (ior, roughness) cell
  float ior_weight_ = 0.0f, roughness_weight_ = 0.0f;  // toward the upper corner
};

}  // namespace pxf
