#include "pathtracer/bsdf.h"

#include <algorithm>
#include <cmath>

#include "pathtracer/ggx_albedo.h"
#include "pathtracer/sheen.h"
#include "scene/material.h"
#include "scene/texture.h"

namespace pxf {
namespace {

inline float saturate(float x) { return std::min(std::max(x, 0.0f), 1.0f); }

// Schlick's (1 - cos)^5, the weight of f90 against f0.
inline float schlick_weight(float cos_theta) {
  const float m = saturate(1.0f - cos_theta), m2 = m * m;
  return m2 * m2 * m;
}

constexpr float kCoatF0 = 0.04f;  // KHR_materials_clearcoat: ior 1.5, ((1.5 - 1) / (1.5 + 1))^2

inline glm::vec3 schlick(glm::vec3 f0, float f90, float cos_theta) {
  return f0 + (glm::vec3(f90) - f0) * schlick_weight(cos_theta);
}

// A smooth or textured parameter is "delta-capable" only when it is a constant factor.
bool constant(const TextureRef& ref) { return !ref.valid(); }

// A lobe's normal n turned to wo's side of the face (ng faces wo); the face itself where wo is below
// n's horizon (interpolated or mapped normals can put it there).
// a or b, chosen per component: a select of values that the compiler keeps in registers, where
// `c ? a : b` of two vectors became a load through a pointer to one of them, which stalled on the
// stores that had just written them (a large share of the Bsdf constructor's time).
inline glm::vec3 select(bool c, glm::vec3 a, glm::vec3 b) {
  return glm::vec3(c ? a.x : b.x, c ? a.y : b.y, c ? a.z : b.z);
}

glm::vec3 normal_facing(glm::vec3 n, glm::vec3 ng, glm::vec3 wo) {
  const glm::vec3 facing = select(glm::dot(n, ng) >= 0.0f, n, -n);
  return select(glm::dot(wo, facing) > 1e-4f, facing, ng);
}

// wo in a lobe's frame, kept just above its horizon.
glm::vec3 local_view(const Frame& frame, glm::vec3 wo) {
  glm::vec3 local = frame.to_local(wo);
  local.z = std::max(local.z, 1e-6f);
  return local;
}

}  // namespace

// Reads exactly the slots of bsdf_texture_slots (scene/material.h).
BsdfParams eval_material(const Scene& scene, const Material& m, glm::vec2 uv0, glm::vec2 uv1,
                         glm::vec4 vertex_color, float uv_width) {
  const auto texture = [&](const TextureRef& ref) { return eval_texture(scene, ref, uv0, uv1, glm::vec4(1.0f), uv_width); };
  BsdfParams p;
  glm::vec4 base = m.base_color * texture(m.base_color_texture) * vertex_color;
  p.base_color = glm::vec3(base);
  glm::vec4 mr = texture(m.metallic_roughness_texture);
  p.metallic = saturate(m.metallic * mr.b);
  p.roughness = saturate(m.roughness * mr.g);
  p.transmission = saturate(m.transmission * texture(m.transmission_texture).r);
  p.ior = m.ior >= 1.0f ? m.ior : 1.5f;  // glTF allows ior 0 (= "no refraction"); keep it sane
  p.specular = saturate(m.specular * texture(m.specular_texture).a);
  p.specular_color = m.specular_color * glm::vec3(texture(m.specular_color_texture));
  p.clearcoat = saturate(m.clearcoat * texture(m.clearcoat_texture).r);
  p.clearcoat_roughness = saturate(m.clearcoat_roughness * texture(m.clearcoat_roughness_texture).g);
  p.sheen_color = m.sheen_color * glm::vec3(texture(m.sheen_color_texture));
  p.sheen_roughness = saturate(m.sheen_roughness * texture(m.sheen_roughness_texture).a);
  return p;
}

bool eval_material_is_constant(const Material& m) {  // the textures eval_material() reads
  const auto slots = bsdf_texture_slots(m);
  return std::all_of(slots.begin(), slots.end(), [](const TextureRef* ref) { return constant(*ref); });
}

glm::vec3 eval_emission(const Scene& scene, const Material& m, glm::vec2 uv0, glm::vec2 uv1) {
  if (!m.is_emissive()) return glm::vec3(0.0f);
  return m.emissive * glm::vec3(eval_texture(scene, m.emissive_texture, uv0, uv1));
}

float eval_opacity(const Scene& scene, const Material& m, glm::vec2 uv0, glm::vec2 uv1, float vertex_alpha) {
  return m.base_color.a * eval_texture(scene, m.base_color_texture, uv0, uv1).a * vertex_alpha;
}

float ggx_d(glm::vec3 h, float alpha) {
  if (h.z <= 0.0f) return 0.0f;
  float a2 = alpha * alpha;
  float t = h.z * h.z * (a2 - 1.0f) + 1.0f;
  return a2 / (kPi * t * t);
}

float ggx_lambda(glm::vec3 w, float alpha) {
  float z2 = w.z * w.z;
  if (z2 <= 0.0f) return 1e30f;
  float tan2 = std::max(0.0f, 1.0f - z2) / z2;
  return 0.5f * (-1.0f + std::sqrt(1.0f + alpha * alpha * tan2));
}

// Visible-normal sampling (Heitz 2018, "Sampling the GGX Distribution of Visible Normals").
glm::vec3 ggx_sample_vndf(glm::vec3 wo, float alpha, glm::vec2 u) {
  glm::vec3 vh = glm::normalize(glm::vec3(alpha * wo.x, alpha * wo.y, wo.z));
  float lensq = vh.x * vh.x + vh.y * vh.y;
  glm::vec3 t1 = lensq > 0.0f ? glm::vec3(-vh.y, vh.x, 0.0f) / std::sqrt(lensq) : glm::vec3(1.0f, 0.0f, 0.0f);
  glm::vec3 t2 = glm::cross(vh, t1);
  float r = std::sqrt(u.x);
  float phi = 2.0f * kPi * u.y;
  float p1 = r * std::cos(phi);
  float p2 = r * std::sin(phi);
  float s = 0.5f * (1.0f + vh.z);
  p2 = (1.0f - s) * std::sqrt(std::max(0.0f, 1.0f - p1 * p1)) + s * p2;
  glm::vec3 nh = p1 * t1 + p2 * t2 + std::sqrt(std::max(0.0f, 1.0f - p1 * p1 - p2 * p2)) * vh;
  return glm::normalize(glm::vec3(alpha * nh.x, alpha * nh.y, std::max(1e-6f, nh.z)));
}

float fresnel_dielectric(float cos_i, float eta) {
  float sin2_t = (1.0f - cos_i * cos_i) / (eta * eta);
  if (sin2_t >= 1.0f) return 1.0f;  // total internal reflection
  float cos_t = std::sqrt(1.0f - sin2_t);
  float rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  float rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  return 0.5f * (rs * rs + rp * rp);
}

float ggx_vndf_pdf(glm::vec3 wo, glm::vec3 h, float alpha) {
  const float cos_oh = glm::dot(wo, h);
  if (!(cos_oh > 0.0f) || !(wo.z > 0.0f)) return 0.0f;
  return ggx_d(h, alpha) * cos_oh / ((1.0f + ggx_lambda(wo, alpha)) * wo.z);
}

BsdfMaterial bsdf_material(const BsdfParams& params) {
  BsdfMaterial k;
  k.params = params;
  const float m = params.metallic, t = params.transmission;
  const float c_diffuse = (1.0f - m) * (1.0f - t);
  k.c_glass = (1.0f - m) * t;
  k.glossy_delta = params.roughness < kDeltaRoughness;
  // An interface without refraction has no half vector for its transmission: it passes light
  // straight through, a delta lobe whatever the roughness (pbrt does the same).
  k.glass_delta = k.glossy_delta || std::abs(params.ior - 1.0f) < 1e-3f;
  k.alpha = std::max(params.roughness * params.roughness, kMinAlpha);
  const float r0 = (params.ior - 1.0f) / (params.ior + 1.0f);
  k.f0_dielectric = glm::min(glm::vec3(r0 * r0) * params.specular_color, glm::vec3(1.0f)) * params.specular;
  k.f90_dielectric = params.specular;
  // metallic schlick(base, 1) + c_diffuse schlick(f0, f90), both f0 + (f90 - f0) schlick_weight.
  k.fresnel_at_0 = m * params.base_color + c_diffuse * k.f0_dielectric;
  k.fresnel_slope = m * (glm::vec3(1.0f) - params.base_color) + c_diffuse * (glm::vec3(k.f90_dielectric) - k.f0_dielectric);
  k.diffuse_albedo = c_diffuse * params.base_color * kInvPi;
  k.clearcoat = params.clearcoat;
  k.coat_delta = params.clearcoat_roughness < kDeltaRoughness;
  k.coat_alpha = std::max(params.clearcoat_roughness * params.clearcoat_roughness, kMinAlpha);
  k.sheen_color = glm::max(params.sheen_color, glm::vec3(0.0f));
  k.sheen_alpha = sheen_alpha(params.sheen_roughness);
  return k;
}

Bsdf::Bsdf(const BsdfMaterial& k, glm::vec3 shading_normal, glm::vec3 geometric_normal, glm::vec3 wo, bool front_face,
           glm::vec3 coat_normal)
    : base_color_(k.params.base_color),
      ior_(k.params.ior),
      alpha_(k.alpha),
      glossy_delta_(k.glossy_delta),
      glass_delta_(k.glass_delta),
      front_face_(front_face),
      c_glass_(k.c_glass),
      fresnel_at_0_(k.fresnel_at_0),
      fresnel_slope_(k.fresnel_slope) {
  ng_ = glm::dot(wo, geometric_normal) >= 0.0f ? geometric_normal : -geometric_normal;
  const glm::vec3 ns = normal_facing(shading_normal, ng_, wo);
  frame_ = Frame::from_normal(ns);
  wo_local_ = local_view(frame_, wo);
  lambda_o_ = ggx_lambda(wo_local_, alpha_);
  g1_o_ = 1.0f / (1.0f + lambda_o_);
  // The coat reflects clearcoat * E_coat of the light, the sheen below it sheen_color * E_sheen of
  // the rest (scaling what is below by 1 - max(sheen_color) E_sheen), and the base gets the rest.
  const float coat_albedo = set_up_coat(k, coat_normal, ns, wo);
  const float coat_share = 1.0f - clearcoat_ * coat_albedo;
  const float sheen_albedo_o = set_up_sheen(k, coat_share);
  const float base_share = coat_share * std::max(0.0f, 1.0f - max_component(k.sheen_color) * sheen_albedo_o);
  const glm::vec3 glossy_albedo = set_up_base(k, base_share);
  // Never 0 where the sheen is evaluated (its albedo vanishes at normal incidence for low roughness),
  // so that the directions it reflects into can be sampled.
  const float w_sheen = luminance(sheen_factor_) * std::max(sheen_albedo_o, 1e-3f);
  choose_lobes(luminance(diffuse_factor_) * kPi, luminance(glossy_albedo), w_sheen, clearcoat_ * coat_albedo, c_glass_);
  if (black_) return;
  // The sheen lobe reflects sheen_color coat_share min(E_sheen, 1) (set_up_sheen scales it down
  // where E_sheen exceeds 1).
  nondelta_albedo_ = diffuse_factor_ * kPi + k.sheen_color * (coat_share * sheen_albedo_o);
  if (!glossy_delta_) nondelta_albedo_ += glossy_albedo;
  if (!coat_delta_) nondelta_albedo_ += glm::vec3(clearcoat_ * coat_albedo);
  if (!glass_delta_ && p_glass_ > 0.0f) nondelta_albedo_ += set_up_glass_compensation();
  inv_4cos_o_ = 1.0f / (4.0f * wo_local_.z);
  glossy_pdf_scale_ = p_glossy_ * inv_4cos_o_ * g1_o_;
}

// The sheen under the coat: its albedo at wo (at most 1); 0 without a sheen.
float Bsdf::set_up_sheen(const BsdfMaterial& k, float coat_share) {
  if (!(max_component(k.sheen_color) > 0.0f)) return 0.0f;
  sheen_alpha_ = k.sheen_alpha;
  // Near grazing at sheen roughness below ~0.2 the lobe's albedo exceeds 1 (up to 1.41, the
  // visibility's fit): scaled down there, so that it never reflects more than it receives.
  const float albedo = sheen_albedo(wo_local_.z, sheen_alpha_);
  sheen_factor_ = k.sheen_color * (albedo > 1.0f ? coat_share / albedo : coat_share);
  return std::min(albedo, 1.0f);
}

// The base's lobes, scaled by the share of the light the layers above leave them. Returns the
// albedo of the (compensated) GGX reflection lobe.
glm::vec3 Bsdf::set_up_base(const BsdfMaterial& k, float base_share) {
  const float cos_o = wo_local_.z;
  // The single-scattering GGX albedo at wo; a delta mirror reflects everything, with Schlick's weight.
  const GgxAlbedo e = glossy_delta_ ? GgxAlbedo{1.0f, schlick_weight(cos_o)} : ggx_albedo(cos_o, alpha_);
  const float missing = 1.0f / std::max(e.total, 1e-2f) - 1.0f;  // 1 / E - 1: the multiple-scattering share
  glossy_compensation_ = (glm::vec3(1.0f) + fresnel_at_0_ * missing) * base_share;
  // The Lambert layer gets what the dielectric specular layer (compensated the same way) leaves.
  const glm::vec3 specular_albedo = (k.f0_dielectric * e.total + (glm::vec3(k.f90_dielectric) - k.f0_dielectric) * e.schlick) *
                                    (glm::vec3(1.0f) + k.f0_dielectric * missing);
  diffuse_factor_ = k.diffuse_albedo * glm::max(glm::vec3(1.0f) - specular_albedo, glm::vec3(0.0f)) * base_share;
  c_glass_ *= base_share;
  return (fresnel_at_0_ * e.total + fresnel_slope_ * e.schlick) * glossy_compensation_;
}

// The rough glass's compensation (Kulla and Conty 2017). Single scattering sends on E(cos_o) of the
// light (glass_albedo.h: reflected and transmitted, in energy); the lobe
//   f_ms = (1 - E_s(cos_o)) (1 - E_t(cos_i)) / (pi (1 - Eavg_t)) x r_s on wo's side t = s
//                                                               x (1 - r_s) / eta^2 across, t = s'
// (E_s the albedo seen from side s, Eavg its cosine-weighted average) sends on the rest, 1 - E_s,
// the share r_s reflected. The split is theirs: 1 - r_s = x (1 - Favg_s) with Favg the smooth
// interface's average Fresnel, and x chosen so that both sides agree (reciprocity: f(wo, wi) /
// eta_o^2 = f(wi, wo) / eta_i^2): x = b / (a + b), a = (1 - Favg_s) / (1 - Eavg_s'), b = eta^2 (1 -
// Favg_s') / (1 - Eavg_s). From the other side the same formula gives 1 - x. Returns the lobe's
// directional albedo in energy, c_glass (R + T base), single and multiple scattering together.
glm::vec3 Bsdf::set_up_glass_compensation() {
  glass_ss_pdf_scale_ = p_glass_;
  glass_albedo_ = GlassAlbedoLookup(alpha_, ior_);
  glass_side_ = front_face_ ? 0 : 1;
  const GlassAlbedo e = glass_albedo_.at(glass_side_, wo_local_.z);
  float reflected = e.reflected, transmitted = e.total - e.reflected;
#ifndef PXF_CYCLES_GLASS_FRESNEL  // Cycles' Glass BSDF, which that build matches, is not compensated
  const int side = glass_side_, other = 1 - side;
  const float loss_here = 1.0f - glass_albedo_.average(side), loss_there = 1.0f - glass_albedo_.average(other);
  const float lost = 1.0f - e.total;
  // Below this the table holds no loss worth a lobe (it is printed to 5 decimals); the test is the
  // same from both sides, so the lobe stays reciprocal.
  constexpr float kMinLoss = 1e-5f;
  if (loss_here > kMinLoss && loss_there > kMinLoss && lost > 0.0f) {
    const float eta = this->eta(), f_here = glass_albedo_.fresnel_average(side), f_there = glass_albedo_.fresnel_average(other);
    const float a = (1.0f - f_here) / loss_there, b = eta * eta * (1.0f - f_there) / loss_here;
    glass_ms_reflect_ = 1.0f - b / (a + b) * (1.0f - f_here);
    glass_ms_prob_ = lost;
    glass_ss_pdf_scale_ = p_glass_ * (1.0f - lost);
    glass_ms_[0] = c_glass_ * lost * glass_ms_reflect_ / (kPi * loss_here);
    glass_ms_[1] = c_glass_ * lost * (1.0f - glass_ms_reflect_) / (kPi * loss_there * eta * eta);
    glass_ms_pdf_[0] = p_glass_ * lost * glass_ms_reflect_ / (kPi * loss_here);
    glass_ms_pdf_[1] = p_glass_ * lost * (1.0f - glass_ms_reflect_) / (kPi * loss_there);
    reflected += lost * glass_ms_reflect_;
    transmitted += lost * (1.0f - glass_ms_reflect_);
  }
#endif
  return c_glass_ * (glm::vec3(reflected) + transmitted * base_color_);
}

// Lobe selection probabilities in proportion to the lobes' weights (their albedos at wo).
void Bsdf::choose_lobes(float w_diffuse, float w_glossy, float w_sheen, float w_coat, float w_glass) {
  w_diffuse = std::max(0.0f, w_diffuse);
  w_glossy = std::max(0.0f, w_glossy);
  w_sheen = std::max(0.0f, w_sheen);
  w_coat = std::max(0.0f, w_coat);
  w_glass = std::max(0.0f, w_glass);
  const float total = w_diffuse + w_glossy + w_sheen + w_coat + w_glass;
  black_ = !(total > 0.0f);
  if (black_) return;
  p_diffuse_ = w_diffuse / total;
  p_glossy_ = w_glossy / total;
  p_sheen_ = w_sheen / total;
  p_coat_ = w_coat / total;
  p_glass_ = w_glass / total;
  has_nondelta_ = p_diffuse_ > 0.0f || p_sheen_ > 0.0f || (p_glossy_ > 0.0f && !glossy_delta_) ||
                  (p_coat_ > 0.0f && !coat_delta_) || (p_glass_ > 0.0f && !glass_delta_);
}

// The coat's frame at wo and its compensated albedo (F0 0.04, ior 1.5); 0 without a coat. The
// coat's normal is coat_normal, or the base's shading normal ns where it is zero (no coat normal
// map); chosen after the coat test, so that a material without a coat does not wait on ns.
float Bsdf::set_up_coat(const BsdfMaterial& k, glm::vec3 coat_normal, glm::vec3 ns, glm::vec3 wo) {
  clearcoat_ = k.clearcoat;
  if (!(clearcoat_ > 0.0f)) return 0.0f;
  if (!(glm::dot(coat_normal, coat_normal) > 0.0f)) coat_normal = ns;
  coat_alpha_ = k.coat_alpha;
  coat_delta_ = k.coat_delta;
  coat_frame_ = Frame::from_normal(normal_facing(coat_normal, ng_, wo));
  coat_wo_local_ = local_view(coat_frame_, wo);
  coat_lambda_o_ = ggx_lambda(coat_wo_local_, coat_alpha_);
  const float cos_o = coat_wo_local_.z;
  const GgxAlbedo e = coat_delta_ ? GgxAlbedo{1.0f, schlick_weight(cos_o)} : ggx_albedo(cos_o, coat_alpha_);
  coat_compensation_ = 1.0f + kCoatF0 * (1.0f / std::max(e.total, 1e-2f) - 1.0f);
  return (kCoatF0 * e.total + (1.0f - kCoatF0) * e.schlick) * coat_compensation_;
}

// Fresnel of the GGX layer: the conductor and the dielectric specular share one microfacet lobe.
glm::vec3 Bsdf::glossy_fresnel(float cos_oh) const {
  return fresnel_at_0_ + fresnel_slope_ * schlick_weight(cos_oh);
}

glm::vec3 Bsdf::eval_local(glm::vec3 wi, float* pdf) const {
  *pdf = 0.0f;
  if (wi.z < 0.0f) {
    if (!(p_glass_ > 0.0f) || glass_delta_) return glm::vec3(0.0f);
    const glm::vec3 f = eval_glass_transmission(wi, pdf);
    return glass_ms_prob_ > 0.0f ? f + eval_glass_compensation(wi, pdf) : f;
  }
  if (wi.z == 0.0f) return glm::vec3(0.0f);
  glm::vec3 f = diffuse_factor_ * wi.z;
  *pdf = (p_diffuse_ + p_sheen_) * wi.z * kInvPi;  // the sheen is cosine-sampled too
  if (p_sheen_ > 0.0f) f += eval_sheen(wi);
  const bool glossy = p_glossy_ > 0.0f && !glossy_delta_, glass = p_glass_ > 0.0f && !glass_delta_;
  if (glossy || glass) {  // the GGX reflection lobes share the half vector
    glm::vec3 h = glm::normalize(wo_local_ + wi);
    float d = ggx_d(h, alpha_);
    float g2 = 1.0f / (1.0f + lambda_o_ + ggx_lambda(wi, alpha_));
    float spec = d * g2 * inv_4cos_o_;  // D G2 / (4 cos_o cos_i), times cos_i
    float cos_oh = std::max(0.0f, glm::dot(wo_local_, h));
    if (glossy) {
      f += glossy_fresnel(cos_oh) * glossy_compensation_ * spec;
      *pdf += glossy_pdf_scale_ * d;  // VNDF: G1(wo) D / (4 cos_o)
    }
    if (glass) {  // reflected with probability F(wo.h) of the sampled microfacet
      float fresnel = glass_fresnel(cos_oh);
      f += glm::vec3(c_glass_ * fresnel * spec);
      *pdf += glass_ss_pdf_scale_ * fresnel * g1_o_ * d * inv_4cos_o_;
      if (glass_ms_prob_ > 0.0f) f += eval_glass_compensation(wi, pdf);
    }
  }
  return f;
}

// Walter et al. 2007's refraction through a GGX microfacet (pbrt-v4's DielectricBxDF), tinted by
// the base color and compressed by eta^2 like the smooth glass's.
glm::vec3 Bsdf::eval_glass_transmission(glm::vec3 wi, float* pdf) const {
  const float eta = this->eta();
  glm::vec3 h = wo_local_ + wi * eta;  // the generalized half vector
  const float length2 = glm::dot(h, h);
  if (!(length2 > 1e-12f)) return glm::vec3(0.0f);
  h *= 1.0f / std::sqrt(length2);
  if (h.z < 0.0f) h = -h;
  const float cos_oh = glm::dot(wo_local_, h), cos_ih = glm::dot(wi, h);
  if (cos_oh <= 0.0f || cos_ih >= 0.0f) return glm::vec3(0.0f);  // a microfacet seen from its back
  const float transmitted = 1.0f - glass_fresnel(cos_oh);
  const float denom = cos_ih + cos_oh / eta;
  const float jacobian = -cos_ih / (denom * denom);  // d omega_h / d omega_i
  if (!(transmitted > 0.0f) || !std::isfinite(jacobian)) return glm::vec3(0.0f);
  const float d = ggx_d(h, alpha_);
  const float g2 = 1.0f / (1.0f + lambda_o_ + ggx_lambda(wi, alpha_));
  const float cos_o = wo_local_.z;
  *pdf += glass_ss_pdf_scale_ * transmitted * g1_o_ * d * cos_oh / cos_o * jacobian;
  return base_color_ * (c_glass_ * transmitted * d * g2 * cos_oh * jacobian / (cos_o * eta * eta));
}

// The compensation lobe at wi (either side): set_up_glass_compensation's f_ms cos, and its pdf.
glm::vec3 Bsdf::eval_glass_compensation(glm::vec3 wi, float* pdf) const {
  const int across = wi.z < 0.0f ? 1 : 0;
  const float cos_i = std::abs(wi.z);
  const float shape = (1.0f - glass_albedo_.at(across ? 1 - glass_side_ : glass_side_, cos_i).total) * cos_i;
  *pdf += glass_ms_pdf_[across] * shape;
  return across ? base_color_ * (glass_ms_[1] * shape) : glm::vec3(glass_ms_[0] * shape);
}

glm::vec3 Bsdf::eval(glm::vec3 wi, float* pdf) const {
  *pdf = 0.0f;
  if (black_) return glm::vec3(0.0f);
  // Reflection stays on wo's side of the face, transmission crosses it: light never passes through
  // an opaque face, and the shading normal may not disagree with the face about the side.
  const glm::vec3 local = frame_.to_local(wi);
  const float side = glm::dot(wi, ng_);
  glm::vec3 f(0.0f);
  if ((local.z > 0.0f && side > 0.0f) || (local.z < 0.0f && side < 0.0f)) f = eval_local(local, pdf);
  if (p_coat_ > 0.0f && !coat_delta_ && side > 0.0f) f += eval_coat(coat_frame_.to_local(wi), pdf);
  return f;
}

glm::vec3 Bsdf::eval_sheen(glm::vec3 wi) const {
  const glm::vec3 h = glm::normalize(wo_local_ + wi);
  return sheen_factor_ * (charlie_d(h.z, sheen_alpha_) * sheen_visibility(wo_local_.z, wi.z, sheen_alpha_) * wi.z);
}

glm::vec3 Bsdf::eval_coat(glm::vec3 wi, float* pdf) const {
  if (wi.z <= 0.0f) return glm::vec3(0.0f);
  const glm::vec3& wo = coat_wo_local_;
  const glm::vec3 h = glm::normalize(wo + wi);
  const float d = ggx_d(h, coat_alpha_);
  const float g2 = 1.0f / (1.0f + coat_lambda_o_ + ggx_lambda(wi, coat_alpha_));
  const float inv_4cos_o = 1.0f / (4.0f * wo.z);
  const float fresnel = kCoatF0 + (1.0f - kCoatF0) * schlick_weight(std::max(0.0f, glm::dot(wo, h)));
  *pdf += p_coat_ * d * inv_4cos_o / (1.0f + coat_lambda_o_);  // VNDF: G1(wo) D / (4 cos_o)
  return glm::vec3(clearcoat_ * coat_compensation_ * fresnel * d * g2 * inv_4cos_o);
}

glm::vec3 Bsdf::eval(glm::vec3 wi) const {
  float pdf;
  return eval(wi, &pdf);
}

float Bsdf::pdf(glm::vec3 wi) const {
  float pdf;
  eval(wi, &pdf);
  return pdf;
}

bool Bsdf::finish_nondelta_sample(glm::vec3 wi, bool transmitted, BsdfSample* out) const {
  out->wi = wi;
  glm::vec3 f = eval(out->wi, &out->pdf);
  if (!(out->pdf > 0.0f)) return false;
  out->weight = f / out->pdf;
  out->delta = false;
  out->transmitted = transmitted;
  return true;
}

bool Bsdf::sample(float u_lobe, glm::vec2 u, BsdfSample* out) const {
  if (black_) return false;
  const glm::vec3& wo = wo_local_;
  if (u_lobe < p_diffuse_) return finish_nondelta_sample(frame_.to_world(sample_cosine_hemisphere(u)), false, out);
  if (u_lobe < p_diffuse_ + p_glossy_) {
    if (glossy_delta_) {  // perfect mirror branch
      glm::vec3 wi(-wo.x, -wo.y, wo.z);
      out->wi = frame_.to_world(wi);
      out->weight = glossy_fresnel(wo.z) * glossy_compensation_ / p_glossy_;  // compensation 1 x the base's share
      out->pdf = 0.0f;
      out->delta = true;
      out->transmitted = false;
      return glm::dot(out->wi, ng_) > 0.0f;
    }
    glm::vec3 wi = glm::reflect(-wo, ggx_sample_vndf(wo, alpha_, u));
    return wi.z > 0.0f && finish_nondelta_sample(frame_.to_world(wi), false, out);
  }
  // The sheen is broad (its D peaks at grazing half vectors): cosine sampling, like the diffuse lobe.
  if (u_lobe < p_diffuse_ + p_glossy_ + p_sheen_)
    return finish_nondelta_sample(frame_.to_world(sample_cosine_hemisphere(u)), false, out);
  if (u_lobe < p_diffuse_ + p_glossy_ + p_sheen_ + p_coat_) return sample_coat(u, out);
  if (!(p_glass_ > 0.0f)) return false;
  if (glass_delta_) return sample_smooth_glass(u, out);
  // The rest of u_lobe's interval picks reflection or refraction.
  const float u_choice = std::min((u_lobe - p_diffuse_ - p_glossy_ - p_sheen_ - p_coat_) / p_glass_, 0x1.fffffep-1f);
  return sample_rough_glass(u_choice, u, out);
}

bool Bsdf::sample_coat(glm::vec2 u, BsdfSample* out) const {
  const glm::vec3& wo = coat_wo_local_;
  if (coat_delta_) {  // a mirror coat
    out->wi = coat_frame_.to_world(glm::vec3(-wo.x, -wo.y, wo.z));
    out->weight = glm::vec3(clearcoat_ * (kCoatF0 + (1.0f - kCoatF0) * schlick_weight(wo.z)) / p_coat_);
    out->pdf = 0.0f;
    out->delta = true;
    out->transmitted = false;
    return glm::dot(out->wi, ng_) > 0.0f;
  }
  const glm::vec3 wi = glm::reflect(-wo, ggx_sample_vndf(wo, coat_alpha_, u));
  return wi.z > 0.0f && finish_nondelta_sample(coat_frame_.to_world(wi), false, out);
}

// Built with PXF_CYCLES_GLASS_FRESNEL (CMake option, scripts/cycles_compare.sh only), the split
// between reflection and refraction is Cycles 3.x's Glass BSDF's instead: the Fresnel of the macro
// normal, F(wo.n), for every microfacet. docs/materials.md compares the two against Cycles.
float Bsdf::glass_fresnel(float cos_oh) const {
#ifdef PXF_CYCLES_GLASS_FRESNEL
  static_cast<void>(cos_oh);
  return fresnel_dielectric(wo_local_.z, eta());
#else
  return fresnel_dielectric(cos_oh, eta());
#endif
}

// The compensation lobe with probability glass_ms_prob_; else a visible microfacet normal, then
// reflection with probability F(wo.h), else refraction through it.
bool Bsdf::sample_rough_glass(float u_choice, glm::vec2 u, BsdfSample* out) const {
  const float single = 1.0f - glass_ms_prob_;
  if (u_choice >= single) return sample_glass_compensation((u_choice - single) / glass_ms_prob_, u, out);
  u_choice /= single;
  const glm::vec3& wo = wo_local_;
  const glm::vec3 h = ggx_sample_vndf(wo, alpha_, u);
  const float cos_oh = glm::dot(wo, h);
  if (!(cos_oh > 0.0f)) return false;
  const float eta = this->eta();
  if (u_choice < glass_fresnel(cos_oh)) {
    const glm::vec3 wi = glm::reflect(-wo, h);
    return wi.z > 0.0f && finish_nondelta_sample(frame_.to_world(wi), false, out);
  }
  const float sin2_t = (1.0f - cos_oh * cos_oh) / (eta * eta);
  if (sin2_t >= 1.0f) return false;  // total internal reflection (F = 1: not reached)
  const float cos_t = std::sqrt(1.0f - sin2_t);
  const glm::vec3 wi = glm::normalize(-wo / eta + (cos_oh / eta - cos_t) * h);
  return wi.z < 0.0f && finish_nondelta_sample(frame_.to_world(wi), true, out);
}

// Reflection with probability glass_ms_reflect_, else transmission; cos theta_i in proportion to the
// loss 1 - E on wi's side, so that the lobe's own weight is constant; the azimuth uniform.
bool Bsdf::sample_glass_compensation(float u_choice, glm::vec2 u, BsdfSample* out) const {
  const bool across = u_choice >= glass_ms_reflect_;
  const float cos_i = glass_albedo_.sample_loss_cos(across ? 1 - glass_side_ : glass_side_, u.x);
  if (!(cos_i > 0.0f)) return false;
  const float sin_i = std::sqrt(std::max(0.0f, 1.0f - cos_i * cos_i)), phi = 2.0f * kPi * u.y;
  const glm::vec3 wi(sin_i * std::cos(phi), sin_i * std::sin(phi), across ? -cos_i : cos_i);
  return finish_nondelta_sample(frame_.to_world(wi), across, out);
}

// Reflect with probability F, else refract (tinted by the base color).
bool Bsdf::sample_smooth_glass(glm::vec2 u, BsdfSample* out) const {
  const glm::vec3& wo = wo_local_;
  float eta = this->eta();
  float cos_i = wo.z;
  float fresnel = fresnel_dielectric(cos_i, eta);
  glm::vec3 wi;
  glm::vec3 weight;
  if (u.x < fresnel) {
    wi = glm::vec3(-wo.x, -wo.y, wo.z);
    weight = glm::vec3(c_glass_ / p_glass_);
    out->transmitted = false;
  } else {
    float sin2_t = (1.0f - cos_i * cos_i) / (eta * eta);
    float cos_t = std::sqrt(std::max(0.0f, 1.0f - sin2_t));
    wi = -wo / eta + (cos_i / eta - cos_t) * glm::vec3(0.0f, 0.0f, 1.0f);
    // Radiance is compressed by eta^2 entering a denser medium (and expanded leaving it).
    weight = base_color_ * (c_glass_ / (p_glass_ * eta * eta));
    out->transmitted = true;
  }
  out->wi = glm::normalize(frame_.to_world(wi));
  out->weight = weight;
  out->pdf = 0.0f;
  out->delta = true;
  return true;
}

std::vector<SurfaceLobe> Bsdf::lobes() const {
  const SurfaceLobe all[] = {{"diffuse", p_diffuse_, false}, {"glossy", p_glossy_, glossy_delta_},
                             {"sheen", p_sheen_, false},      {"clearcoat", p_coat_, coat_delta_},
                             {"glass", p_glass_, glass_delta_}};
  std::vector<SurfaceLobe> picked;
  for (const SurfaceLobe& lobe : all)
    if (lobe.probability > 0.0f) picked.push_back(lobe);
  return picked;
}

}  // namespace pxf
