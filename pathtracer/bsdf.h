// Materials as BSDFs (glTF metallic-roughness + transmission, ior, specular, clearcoat):
//   clearcoat * GGX coat (Schlick, F0 = 0.04, own roughness and normal)
// + (1 - clearcoat * E_coat(cos_o)) * (sheen color * Charlie sheen
//                                       + (1 - max(sheen color) E_sheen(cos_o)) * the base):
//   metallic * GGX conductor (Schlick, F0 = base color)
// + (1 - metallic) * (1 - transmission) * (GGX dielectric specular (F0 from ior and KHR specular)
//                                        + (1 - E_specular(cos_o)) * Lambert(base color))
// + (1 - metallic) * transmission * GGX dielectric (Walter 2007: exact Fresnel, reflection and
//                                     refraction, the refraction tinted by the base color).
// The GGX reflection lobes are energy-compensated (Turquin 2019: scaled by 1 + F0 (1 / E - 1), E
// the single-scattering albedo, ggx_albedo.h); the GGX dielectric by Kulla and Conty's (2017)
// reciprocal lobe (1 - E(cos_o)) (1 - E(cos_i)) / (pi (1 - E_avg)), split between reflection and
// transmission (glass_albedo.h). Roughness below kDeltaRoughness makes the GGX lobes
// delta lobes (a mirror, smooth glass). Lobes are picked stochastically by their albedo at wo;
// pdf() is the combined pdf of the non-delta lobes.
#pragma once
#include <vector>

#include <glm/glm.hpp>
#include "pathtracer/glass_albedo.h"
#include "pathtracer/pathtracer.h"  // SurfaceLobe
#include "pathtracer/sampling.h"
#include "scene/material.h"  // kDeltaRoughness
#include "scene/scene.h"

namespace pxf {

constexpr float kMinAlpha = 1e-3f;  // GGX alpha floor for near-smooth (but not delta) surfaces

// Material parameters at one surface point (textures, vertex colors applied).
struct BsdfParams {
  glm::vec3 base_color{1.0f};
  float metallic = 0.0f;
  float roughness = 1.0f;
  float transmission = 0.0f;
  float ior = 1.5f;
  float specular = 1.0f;
  glm::vec3 specular_color{1.0f};
  float clearcoat = 0.0f;  // KHR_materials_clearcoat
  float clearcoat_roughness = 0.0f;
  glm::vec3 sheen_color{0.0f};  // KHR_materials_sheen
  float sheen_roughness = 0.0f;
};

// The material evaluated at a surface point: base color x texture x vertex color, etc.; its
// textures read at the mip level of the footprint `uv_width` (SurfacePoint::texture_footprint).
BsdfParams eval_material(const Scene& scene, const Material& material, glm::vec2 uv0, glm::vec2 uv1,
                         glm::vec4 vertex_color, float uv_width = 0.0f);
// True when eval_material() reads no texture of the material: its parameters are then the same at
// every point with a white vertex color.
bool eval_material_is_constant(const Material& material);
// Emitted radiance of the material's front side (emissive factor x emissive texture).
glm::vec3 eval_emission(const Scene& scene, const Material& material, glm::vec2 uv0, glm::vec2 uv1);
// Base color alpha x texture alpha x vertex alpha (for MASK cutouts).
float eval_opacity(const Scene& scene, const Material& material, glm::vec2 uv0, glm::vec2 uv1, float vertex_alpha);

// Beer-Lambert transmittance of `distance` scene units inside the material's volume.
inline glm::vec3 volume_transmittance(const Material& material, float distance) {
  return glm::exp(-material.attenuation * distance);
}

// What a Bsdf takes from its material's parameters alone, not from the shading point: computed
// once per untextured material by the integrator (PathTracer::bsdf_material_at), per vertex otherwise.
struct BsdfMaterial {
  BsdfParams params;
  float c_glass = 0.0f;                    // the glass lobe's mixing coefficient
  bool glossy_delta = false;               // roughness below kDeltaRoughness: a mirror lobe
  bool glass_delta = false;                // the same, or ior ~ 1 (no refraction): smooth glass
  float alpha = 1.0f;                      // GGX alpha
  glm::vec3 f0_dielectric{0.0f};           // the dielectric specular's Schlick terms
  float f90_dielectric = 1.0f;
  // glossy_fresnel(c) = fresnel_at_0 + fresnel_slope (1 - c)^5: the metal's and the dielectric's
  // Schlick terms share the power, so their sum is one line.
  glm::vec3 fresnel_at_0{0.0f}, fresnel_slope{0.0f};
  glm::vec3 diffuse_albedo{0.0f};  // c_diffuse * base / pi, c_diffuse = (1 - metallic)(1 - transmission)
  float clearcoat = 0.0f;          // the coat's weight
  bool coat_delta = true;          // clearcoat roughness below kDeltaRoughness: a mirror coat
  float coat_alpha = kMinAlpha;    // the coat's GGX alpha
  glm::vec3 sheen_color{0.0f};
  float sheen_alpha = 1.0f;        // the Charlie distribution's
};
BsdfMaterial bsdf_material(const BsdfParams& params);

struct BsdfSample {
  glm::vec3 wi{0.0f};      // world space, unit
  glm::vec3 weight{0.0f};  // f |cos| / pdf (for a delta branch: its throughput factor)
  float pdf = 0.0f;        // combined solid-angle pdf of the non-delta lobes (0 for delta)
  bool delta = false;      // drawn from a delta lobe (mirror or smooth dielectric)
  bool transmitted = false;
};

class Bsdf {
 public:
  Bsdf() = default;
  // shading_normal and geometric_normal: unit, any orientation (flipped to wo's side here);
  // front_face: wo is on the side the geometric normal points to (outside of a dielectric);
  // coat_normal: the clearcoat's shading normal (zero: shading_normal).
  Bsdf(const BsdfMaterial& material, glm::vec3 shading_normal, glm::vec3 geometric_normal, glm::vec3 wo,
       bool front_face, glm::vec3 coat_normal = glm::vec3(0.0f));
  Bsdf(const BsdfParams& params, glm::vec3 shading_normal, glm::vec3 geometric_normal, glm::vec3 wo,
       bool front_face, glm::vec3 coat_normal = glm::vec3(0.0f))
      : Bsdf(bsdf_material(params), shading_normal, geometric_normal, wo, front_face, coat_normal) {}

  glm::vec3 eval(glm::vec3 wi) const;  // f(wo, wi) |cos(wi)| of the non-delta lobes (wi on either side)
  float pdf(glm::vec3 wi) const;       // combined pdf of the non-delta lobes
  glm::vec3 eval(glm::vec3 wi, float* pdf) const;  // both at once (shares the half-vector work)
  // u_lobe picks the lobe, u the direction. Returns false when no valid direction was drawn.
  bool sample(float u_lobe, glm::vec2 u, BsdfSample* out) const;

  bool is_perfectly_specular() const { return !has_nondelta_; }
  bool has_nondelta() const { return has_nondelta_; }
  float eta() const { return front_face_ ? ior_ : 1.0f / ior_; }  // eta_t / eta_i across the surface
  // The probability that sample() picks the diffuse lobe.
  float diffuse_probability() const { return p_diffuse_; }
  // sample() reads u_lobe only when more than one lobe can be picked, or when the rough glass lobe
  // (which picks reflection or refraction with it) can be.
  bool has_lobe_choice() const {
    return (p_diffuse_ > 0.0f) + (p_glossy_ > 0.0f) + (p_sheen_ > 0.0f) + (p_coat_ > 0.0f) + (p_glass_ > 0.0f) > 1 ||
           (p_glass_ > 0.0f && !glass_delta_);
  }
  bool is_black() const { return black_; }
  // The directional albedo at wo of the non-delta lobes, RGB: the share of light from all
  // directions that they reflect or transmit toward wo. Illumination demodulation divides the
  // light these lobes carry by it (PathSample::albedo), so it counts the specular lobes too. Rough
  // glass counts the energy it transmits (the sample weight times eta^2: the radiance it passes on
  // from a surrounding as bright on both sides, which is eta^2 brighter inside a dense medium).
  glm::vec3 nondelta_albedo() const { return nondelta_albedo_; }
  glm::vec3 shading_normal() const { return frame_.n; }
  // The lobes sample() picks from, each with its probability and whether it is a delta lobe (the
  // explorer's inspector shows them: ProgressiveRenderer::surface_material).
  std::vector<SurfaceLobe> lobes() const;

 private:
  glm::vec3 eval_local(glm::vec3 wi, float* pdf) const;
  glm::vec3 eval_glass_transmission(glm::vec3 wi, float* pdf) const;
  glm::vec3 eval_glass_compensation(glm::vec3 wi, float* pdf) const;  // adds its pdf to *pdf
  glm::vec3 set_up_glass_compensation();
  glm::vec3 eval_coat(glm::vec3 wi_coat, float* pdf) const;  // adds the coat's pdf to *pdf
  float set_up_coat(const BsdfMaterial& material, glm::vec3 coat_normal, glm::vec3 ns, glm::vec3 wo);
  glm::vec3 eval_sheen(glm::vec3 wi) const;  // f cos of the sheen lobe (local, wi.z > 0)
  float set_up_sheen(const BsdfMaterial& material, float coat_share);
  glm::vec3 set_up_base(const BsdfMaterial& material, float base_share);
  void choose_lobes(float w_diffuse, float w_glossy, float w_sheen, float w_coat, float w_glass);
  bool sample_coat(glm::vec2 u, BsdfSample* out) const;
  glm::vec3 glossy_fresnel(float cos_oh) const;
  bool sample_smooth_glass(glm::vec2 u, BsdfSample* out) const;
  bool sample_rough_glass(float u_choice, glm::vec2 u, BsdfSample* out) const;
  bool sample_glass_compensation(float u_choice, glm::vec2 u, BsdfSample* out) const;
  bool finish_nondelta_sample(glm::vec3 wi, bool transmitted, BsdfSample* out) const;
  // The rough glass's Fresnel reflectance at a microfacet seen at cos_oh (Walter et al. 2007).
  float glass_fresnel(float cos_oh) const;

  Frame frame_{};
  glm::vec3 ng_{0.0f};      // geometric normal on wo's side
  glm::vec3 wo_local_{0.0f};
  glm::vec3 base_color_{1.0f};  // the glass lobe's tint
  float ior_ = 1.5f;
  float alpha_ = 1.0f;
  float lambda_o_ = 0.0f;  // Smith Lambda(wo), fixed per shading point
  // Fixed per shading point, so eval_local() divides once per BSDF instead of once per call:
  float inv_4cos_o_ = 0.0f;         // 1 / (4 cos_o)
  float glossy_pdf_scale_ = 0.0f;   // p_glossy G1(wo) / (4 cos_o): the glossy pdf is this times D(h)
  float g1_o_ = 1.0f;               // Smith G1(wo)
  bool glossy_delta_ = false;
  bool glass_delta_ = false;
  bool front_face_ = true;
  float c_glass_ = 0.0f;  // the glass lobe's mixing coefficient
  glm::vec3 fresnel_at_0_{0.0f}, fresnel_slope_{0.0f};  // BsdfMaterial's
  glm::vec3 glossy_compensation_{1.0f};  // Turquin's 1 + F0 (1 / E(cos_o) - 1) of the GGX reflection lobe
  glm::vec3 diffuse_factor_{0.0f};  // c_diffuse * base / pi * (1 - F_dielectric(cos_o))
  // The clearcoat: its own frame (its normal map) and GGX lobe, F = Schlick(0.04, 1).
  Frame coat_frame_{};
  glm::vec3 coat_wo_local_{0.0f};
  float clearcoat_ = 0.0f;
  float coat_alpha_ = 1.0f;
  bool coat_delta_ = false;
  float coat_lambda_o_ = 0.0f;
  float coat_compensation_ = 1.0f;  // Turquin's factor of the coat lobe
  // The sheen: color x Charlie D x Neubelt-Pettineo V, under the coat (times its share).
  glm::vec3 sheen_factor_{0.0f};
  float sheen_alpha_ = 1.0f;
  // Lobe selection probabilities; sample() reads u_lobe in this order.
  float p_diffuse_ = 0.0f, p_glossy_ = 0.0f, p_sheen_ = 0.0f, p_coat_ = 0.0f, p_glass_ = 0.0f;
  bool has_nondelta_ = false;
  bool black_ = true;
  glm::vec3 nondelta_albedo_{0.0f};
  // The rough glass's compensation lobe (Kulla and Conty 2017): the tabulated single-scattering
  // albedo at this roughness and ior, wo's side of it (0 outside), and the lobe's weights:
  // f cos = glass_ms_[t] (1 - E(cos_i)) |cos_i| on wi's side, t = 1 for transmission (tinted by the
  // base), and its pdf glass_ms_pdf_[t] times the same. sample_rough_glass picks it with probability
  // glass_ms_prob_ = 1 - E(cos_o), the single-scattering lobe with the rest (glass_ss_pdf_scale_ =
  // p_glass (1 - glass_ms_prob_)), and its reflection with probability glass_ms_reflect_.
  GlassAlbedoLookup glass_albedo_{};
  int glass_side_ = 0;
  float glass_ms_prob_ = 0.0f, glass_ms_reflect_ = 1.0f, glass_ss_pdf_scale_ = 0.0f;
  float glass_ms_[2] = {0.0f, 0.0f}, glass_ms_pdf_[2] = {0.0f, 0.0f};
};

// GGX helpers (local frame, n = +z), exposed for tests.
float ggx_d(glm::vec3 h, float alpha);
float ggx_lambda(glm::vec3 w, float alpha);
glm::vec3 ggx_sample_vndf(glm::vec3 wo, float alpha, glm::vec2 u);
float fresnel_dielectric(float cos_i, float eta);  // eta = eta_t / eta_i, cos_i >= 0
// Visible-normal pdf of h seen from wo: G1(wo) max(0, wo.h) D(h) / cos_o.
float ggx_vndf_pdf(glm::vec3 wo, glm::vec3 h, float alpha);

}  // namespace pxf
