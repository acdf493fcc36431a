#include "pathtracer/bsdf.h"

#include <algorithm>
#include <cmath>

#include "pathtracer/texture.h"

namespace pxf {
namespace {

inline float saturate(float x) { return std::min(std::max(x, 0.0f), 1.0f); }

// Schlick's (1 - cos)^5, the weight of f90 against f0.
inline float schlick_weight(float cos_theta) {
  const float m = saturate(1.0f - cos_theta), m2 = m * m;
  return m2 * m2 * m;
}

inline glm::vec3 schlick(glm::vec3 f0, float f90, float cos_theta) {
  return f0 + (glm::vec3(f90) - f0) * schlick_weight(cos_theta);
}

// A smooth or textured parameter is "delta-capable" only when it is a constant factor.
bool constant(const TextureRef& ref) { return !ref.valid(); }

}  // namespace

BsdfParams eval_material(const Scene& scene, const Material& m, glm::vec2 uv0, glm::vec2 uv1,
                         glm::vec4 vertex_color) {
  BsdfParams p;
  glm::vec4 base = m.base_color * eval_texture(scene, m.base_color_texture, uv0, uv1) * vertex_color;
  p.base_color = glm::vec3(base);
  glm::vec4 mr = eval_texture(scene, m.metallic_roughness_texture, uv0, uv1);
  p.metallic = saturate(m.metallic * mr.b);
  p.roughness = saturate(m.roughness * mr.g);
  p.transmission = saturate(m.transmission * eval_texture(scene, m.transmission_texture, uv0, uv1).r);
  p.ior = m.ior >= 1.0f ? m.ior : 1.5f;  // glTF allows ior 0 (= "no refraction"); keep it sane
  p.specular = saturate(m.specular * eval_texture(scene, m.specular_texture, uv0, uv1).a);
  p.specular_color = m.specular_color * glm::vec3(eval_texture(scene, m.specular_color_texture, uv0, uv1));
  return p;
}

bool eval_material_is_constant(const Material& m) {  // the textures eval_material() reads
  return constant(m.base_color_texture) && constant(m.metallic_roughness_texture) && constant(m.transmission_texture) &&
         constant(m.specular_texture) && constant(m.specular_color_texture);
}

glm::vec3 eval_emission(const Scene& scene, const Material& m, glm::vec2 uv0, glm::vec2 uv1) {
  if (!m.is_emissive()) return glm::vec3(0.0f);
  return m.emissive * glm::vec3(eval_texture(scene, m.emissive_texture, uv0, uv1));
}

float eval_opacity(const Scene& scene, const Material& m, glm::vec2 uv0, glm::vec2 uv1, float vertex_alpha) {
  return m.base_color.a * eval_texture(scene, m.base_color_texture, uv0, uv1).a * vertex_alpha;
}

bool material_is_perfect_mirror(const Material& m) {
  return constant(m.metallic_roughness_texture) && m.roughness < kDeltaRoughness && m.metallic >= 1.0f - 1e-3f;
}

bool material_is_perfect_specular(const Material& m) {
  if (!constant(m.metallic_roughness_texture) || m.roughness >= kDeltaRoughness) return false;
  bool glass = constant(m.transmission_texture) && m.transmission >= 1.0f - 1e-3f && m.metallic <= 1e-3f;
  return material_is_perfect_mirror(m) || glass;
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

BsdfMaterial bsdf_material(const BsdfParams& params) {
  BsdfMaterial k;
  k.params = params;
  const float m = params.metallic, t = params.transmission;
  const float c_diffuse = (1.0f - m) * (1.0f - t);
  k.c_glass = (1.0f - m) * t;
  k.glossy_delta = params.roughness < kDeltaRoughness;
  k.alpha = std::max(params.roughness * params.roughness, kMinAlpha);
  const float r0 = (params.ior - 1.0f) / (params.ior + 1.0f);
  k.f0_dielectric = glm::min(glm::vec3(r0 * r0) * params.specular_color, glm::vec3(1.0f)) * params.specular;
  k.f90_dielectric = params.specular;
  // metallic schlick(base, 1) + c_diffuse schlick(f0, f90), both f0 + (f90 - f0) schlick_weight.
  k.fresnel_at_0 = m * params.base_color + c_diffuse * k.f0_dielectric;
  k.fresnel_slope = m * (glm::vec3(1.0f) - params.base_color) + c_diffuse * (glm::vec3(k.f90_dielectric) - k.f0_dielectric);
  k.diffuse_albedo = c_diffuse * params.base_color * kInvPi;
  return k;
}

Bsdf::Bsdf(const BsdfMaterial& k, glm::vec3 shading_normal, glm::vec3 geometric_normal, glm::vec3 wo, bool front_face)
    : base_color_(k.params.base_color),
      ior_(k.params.ior),
      alpha_(k.alpha),
      glossy_delta_(k.glossy_delta),
      front_face_(front_face),
      c_glass_(k.c_glass),
      fresnel_at_0_(k.fresnel_at_0),
      fresnel_slope_(k.fresnel_slope) {
  ng_ = glm::dot(wo, geometric_normal) >= 0.0f ? geometric_normal : -geometric_normal;
  glm::vec3 ns = glm::dot(shading_normal, ng_) >= 0.0f ? shading_normal : -shading_normal;
  // Interpolated or mapped normals can put wo below the shading horizon: fall back to the face.
  if (!(glm::dot(wo, ns) > 1e-4f)) ns = ng_;
  frame_ = Frame::from_normal(ns);
  wo_local_ = frame_.to_local(wo);
  wo_local_.z = std::max(wo_local_.z, 1e-6f);
  lambda_o_ = ggx_lambda(wo_local_, alpha_);

  float cos_o = wo_local_.z;
  glm::vec3 fd_o = schlick(k.f0_dielectric, k.f90_dielectric, cos_o);
  diffuse_factor_ = k.diffuse_albedo * (glm::vec3(1.0f) - fd_o);
  float w_diffuse = std::max(0.0f, luminance(diffuse_factor_) * kPi);
  float w_glossy = std::max(0.0f, luminance(glossy_fresnel(cos_o)));
  float w_glass = std::max(0.0f, c_glass_);
  float total = w_diffuse + w_glossy + w_glass;
  black_ = !(total > 0.0f);
  if (black_) return;
  p_diffuse_ = w_diffuse / total;
  p_glossy_ = w_glossy / total;
  p_glass_ = w_glass / total;
  has_nondelta_ = p_diffuse_ > 0.0f || (p_glossy_ > 0.0f && !glossy_delta_);
  inv_4cos_o_ = 1.0f / (4.0f * cos_o);
  glossy_pdf_scale_ = p_glossy_ * inv_4cos_o_ / (1.0f + lambda_o_);
}

// Fresnel of the GGX layer: the conductor and the dielectric specular share one microfacet lobe.
glm::vec3 Bsdf::glossy_fresnel(float cos_oh) const {
  return fresnel_at_0_ + fresnel_slope_ * schlick_weight(cos_oh);
}

glm::vec3 Bsdf::eval_local(glm::vec3 wi, float* pdf) const {
  *pdf = 0.0f;
  if (wi.z <= 0.0f) return glm::vec3(0.0f);
  glm::vec3 f = diffuse_factor_ * wi.z;
  *pdf = p_diffuse_ * wi.z * kInvPi;
  if (p_glossy_ > 0.0f && !glossy_delta_) {
    glm::vec3 h = glm::normalize(wo_local_ + wi);
    float d = ggx_d(h, alpha_);
    float g2 = 1.0f / (1.0f + lambda_o_ + ggx_lambda(wi, alpha_));
    float spec = d * g2 * inv_4cos_o_;  // D G2 / (4 cos_o cos_i), times cos_i
    f += glossy_fresnel(std::max(0.0f, glm::dot(wo_local_, h))) * spec;
    *pdf += glossy_pdf_scale_ * d;  // VNDF: G1(wo) D / (4 cos_o)
  }
  return f;
}

glm::vec3 Bsdf::eval(glm::vec3 wi, float* pdf) const {
  *pdf = 0.0f;
  if (black_ || glm::dot(wi, ng_) <= 0.0f) return glm::vec3(0.0f);  // no light through opaque faces
  return eval_local(frame_.to_local(wi), pdf);
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

bool Bsdf::sample(float u_lobe, glm::vec2 u, BsdfSample* out) const {
  if (black_) return false;
  const glm::vec3& wo = wo_local_;
  if (u_lobe < p_diffuse_ + p_glossy_) {
    bool diffuse = u_lobe < p_diffuse_;
    if (!diffuse && glossy_delta_) {  // perfect mirror branch
      glm::vec3 wi(-wo.x, -wo.y, wo.z);
      out->wi = frame_.to_world(wi);
      out->weight = glossy_fresnel(wo.z) / p_glossy_;
      out->pdf = 0.0f;
      out->delta = true;
      out->transmitted = false;
      return glm::dot(out->wi, ng_) > 0.0f;
    }
    glm::vec3 wi;
    if (diffuse) {
      wi = sample_cosine_hemisphere(u);
    } else {
      glm::vec3 h = ggx_sample_vndf(wo, alpha_, u);
      wi = glm::reflect(-wo, h);
    }
    if (wi.z <= 0.0f) return false;
    out->wi = frame_.to_world(wi);
    if (glm::dot(out->wi, ng_) <= 0.0f) return false;
    glm::vec3 f = eval_local(wi, &out->pdf);
    if (!(out->pdf > 0.0f)) return false;
    out->weight = f / out->pdf;
    out->delta = false;
    out->transmitted = false;
    return true;
  }
  // Smooth dielectric: reflect with probability F, else refract (tinted by the base color).
  float eta = front_face_ ? ior_ : 1.0f / ior_;  // eta_t / eta_i
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

}  // namespace pxf
