#include "pathtracer/caustics/specular_chain_sampler.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "pathtracer/guiding_mixture.h"
#include "pathtracer/sampling.h"
#include "pathtracer/shading.h"

namespace pxf {
namespace {

// The cone from p that holds the sphere: its axis and the cosine of its half angle. False when p
// is inside the sphere or the cone is too narrow to sample in float.
bool target_cone(glm::vec3 center, float radius, glm::vec3 p, glm::vec3* axis, float* cos_max) {
  const glm::vec3 d = center - p;
  const float dist2 = glm::dot(d, d);
  if (!(dist2 > radius * radius)) return false;
  *axis = d / std::sqrt(dist2);
  *cos_max = std::sqrt(std::max(0.0f, 1.0f - radius * radius / dist2));
  return 1.0f - *cos_max > 1e-6f;
}

}  // namespace

SpecularChainSampler::SpecularChainSampler(const EmbreeScene& geometry, const LightSampler& lights,
                                           const BsdfMaterials& materials)
    : geometry_(geometry), lights_(lights), materials_(materials) {
  const Scene& scene = geometry.scene();
  for (unsigned mesh_index = 0; mesh_index < scene.meshes.size(); ++mesh_index) {
    const Mesh& mesh = scene.meshes[mesh_index];
    if (mesh.triangles.empty() || !material_is_perfect_specular(scene.materials[mesh.material])) continue;
    has_perfect_specular_ = true;
    glm::vec3 lo(INFINITY), hi(-INFINITY);
    for (const glm::vec3& p : mesh.positions) {
      lo = glm::min(lo, p);
      hi = glm::max(hi, p);
    }
    Target target;
    target.center = 0.5f * (lo + hi);
    for (const glm::vec3& p : mesh.positions) target.radius = std::max(target.radius, glm::length(p - target.center));
    target.radius *= 1.0001f;
    // Near chains only toward a mesh that fills its bounding sphere's cone: by Cauchy's formula a
    // convex surface's mean projected area is a quarter of its area, so area / (4 pi r^2) is the
    // mean share of the cone it covers (a sphere 1, a cube 0.64; three jars merged into one mesh,
    // as on the kitchen's shelf, 0.2: chains toward them mostly miss the glass).
    double area = 0.0;
    for (unsigned prim = 0; prim < mesh.triangles.size(); ++prim) area += geometry.triangle_area(mesh_index, prim);
    const double sphere_area = 4.0 * kPi * double(target.radius) * double(target.radius);
    if (area >= kNearSpecularMinFill * sphere_area)
      target.near_distance2 = target.radius * target.radius * kNearSpecularDistance2PerRadius2;
    SphereCaster caster;
    if (fit_sphere_caster(mesh.positions, mesh.normals, &caster)) {
      const Material& m = scene.materials[mesh.material];
      caster.mirror = material_is_perfect_mirror(m);
      caster.ior = m.ior;
      target.caster = static_cast<int>(casters_.size());
      target.mirror_caster = caster.mirror;
      casters_.push_back(caster);
    }
    if (std::isfinite(target.radius) && target.radius > 0.0f) {
      mirror_caster_targets_ += target.mirror_caster;
      targets_.push_back(target);
      has_near_targets_ |= target.near_distance2 > 0.0f;
    }
  }
  if (!casters_.empty()) set_up_solved_chains();
}

void SpecularChainSampler::set_up_solved_chains() {
  const size_t count = lights_.emissive_triangle_count();
  if (count == 0 || count > kMaxSolvedChainEmitters) return;
  std::vector<SphereCausticSampler::Emitter> emitters;
  std::vector<float> powers;
  for (size_t i = 0; i < count; ++i) {
    const LightSampler::EmissiveTriangle& t = lights_.triangle(i);
    emitters.push_back({glm::dvec3(t.p0), glm::dvec3(t.e1), glm::dvec3(t.e2), double(t.area)});
    powers.push_back(lights_.triangle_power_pmf(i));
  }
  caustics_ = SphereCausticSampler(std::move(emitters), powers);
  if (!caustics_.empty()) solved_chain_share_ = lights_.has_environment() ? kSolvedChainShareWithEnvironment : 1.0f;
}

bool SpecularChainSampler::Target::near(glm::vec3 p) const {
  const glm::vec3 d = center - p;
  const float d2 = glm::dot(d, d);
  return d2 <= near_distance2 && d2 > radius * radius;
}

bool SpecularChainSampler::Plan::includes(const Target& t, glm::vec3 p) const {
  return targets == Targets::All || (targets == Targets::Near ? t.near(p) : t.mirror_caster);
}

SpecularChainSampler::Plan SpecularChainSampler::plan(glm::vec3 p, const TraceParams& params, bool first_vertex) const {
  Plan plan;
  if (targets_.empty()) return plan;
  if (params.specular_sampling) {
    plan.candidates = static_cast<int>(targets_.size());
    return plan;
  }
  if (!params.specular_chains) return plan;
  if (has_near_targets_ && first_vertex) {
    plan.targets = Plan::Targets::Near;
    for (const Target& t : targets_) plan.candidates += t.near(p);
    if (plan.candidates > 0) return plan;
  }
  if (far_chains()) {
    plan.targets = Plan::Targets::Casters;
    plan.candidates = mirror_caster_targets_;
    plan.probability = kFarCasterChainProbability;
  }
  return plan;
}

float SpecularChainSampler::pdf(glm::vec3 p, glm::vec3 wi, const Plan& plan, const Target* drawn_from,
                                float drawn_pdf) const {
  float sum = 0.0f;
  int candidates = 0;
  for (const Target& t : targets_) {
    if (!plan.includes(t, p)) continue;
    ++candidates;
    glm::vec3 axis;
    float cos_max;
    if (!target_cone(t.center, t.radius, p, &axis, &cos_max) || glm::dot(wi, axis) < cos_max) continue;
    const float cone = 1.0f / (2.0f * kPi * (1.0f - cos_max));
    if (t.caster < 0 || solved_chain_share_ == 0.0f) {
      sum += cone;
    } else {  // every solved direction meets the analytic sphere, inside the bounding one: in the cone
      const float solved = &t == drawn_from ? drawn_pdf : caustics_.pdf(casters_[t.caster], p, wi);
      sum += (1.0f - solved_chain_share_) * cone + solved_chain_share_ * solved;
    }
  }
  return candidates > 0 ? plan.probability * sum / static_cast<float>(candidates) : 0.0f;
}

bool SpecularChainSampler::sample(glm::vec3 p, const Plan& plan, float u_select, glm::vec2 u, Direction* out) const {
  if (u_select >= plan.probability) return false;  // not traced this time
  u_select /= plan.probability;
  // The target: candidate number k of the plan's, chosen uniformly.
  const int n = plan.candidates;
  const int chosen = std::min(n - 1, static_cast<int>(u_select * static_cast<float>(n)));
  // u_select rescaled within the choice: it picks the strategy, then the emitter and the path.
  float u_rest = std::min(std::max(u_select * static_cast<float>(n) - static_cast<float>(chosen), 0.0f), 0x1.fffffep-1f);
  int k = chosen;
  const Target* target = nullptr;
  for (const Target& t : targets_)
    if (plan.includes(t, p) && k-- == 0) {
      target = &t;
      break;
    }
  glm::vec3 axis;
  float cos_max;
  if (!target_cone(target->center, target->radius, p, &axis, &cos_max)) return false;
  const Target* drawn_from = nullptr;
  float drawn_pdf = 0.0f;
  if (target->caster >= 0 && u_rest < solved_chain_share_) {
    if (!caustics_.sample(casters_[target->caster], p, u_rest / solved_chain_share_, u, &out->wi, &drawn_pdf))
      return false;
    drawn_from = target;
  } else {
    const float cos_t = 1.0f - u.x * (1.0f - cos_max), sin_t = std::sqrt(std::max(0.0f, 1.0f - cos_t * cos_t));
    const float phi = 2.0f * kPi * u.y;
    out->wi = glm::normalize(Frame::from_normal(axis).to_world(glm::vec3(std::cos(phi) * sin_t, std::sin(phi) * sin_t, cos_t)));
  }
  out->pdf = pdf(p, out->wi, plan, drawn_from, drawn_pdf);
  return true;
}

glm::vec3 SpecularChainSampler::light(const SurfacePoint& sp, const Bsdf& bsdf, const GuidingMixture& mixture,
                                      glm::vec3 throughput, int vertex, const Plan& plan, PathSampler& sampler,
                                      int max_vertices, uint32_t* rays, bool* through_glass) const {
  const Scene& scene = geometry_.scene();
  const PathSampler::SpecularNumbers numbers = sampler.specular_numbers(vertex);
  Direction d;
  if (!sample(sp.position, plan, numbers.select, numbers.direction, &d)) return glm::vec3(0.0f);
  const glm::vec3 wi = d.wi;
  float bsdf_pdf;
  const glm::vec3 f = bsdf.eval(wi, &bsdf_pdf);
  const float pdf = d.pdf;
  if (!(max_component(f) > 0.0f) || !(pdf > 0.0f)) return glm::vec3(0.0f);
  glm::vec3 t = throughput * f / pdf;
  const float w = power_heuristic(pdf, mixture.pdf(bsdf_pdf, wi));
  glm::vec3 light(0.0f);
  Ray ray{offset_ray_origin(sp.position, sp.geometric_normal, wi), wi};
  // The chain's vertices get the indices the path's own would: the same length limit as BSDF sampling.
  for (int v = vertex + 1; v <= max_vertices; ++v) {
    const Hit hit = geometry_.intersect(ray);
    ++*rays;
    if (!hit.valid()) {
      if (v > vertex + 1 && lights_.has_environment()) light += t * lights_.environment_radiance(ray.direction) * w;
      break;
    }
    const SurfacePoint q = geometry_.surface_point(hit, ray);
    const Material& material = *q.material;
    if (!q.front_face && material.has_volume()) t *= volume_transmittance(material, hit.t);
    // Emission at the first hit is D L (NEE and BSDF sampling); after a specular bounce it is D S+ L.
    if (v > vertex + 1 && emission_visible(material, q)) light += t * eval_emission(scene, material, q.uv0, q.uv1) * w;
    if (!material_is_perfect_specular(material) || v == max_vertices) break;
    BsdfMaterial scratch;
    const BsdfMaterial& lobes = materials_.at(q, &scratch);
    const BsdfParams& p = lobes.params;
    const Bsdf chain_bsdf(lobes, q.shading_normal, q.geometric_normal, -ray.direction, q.front_face, q.clearcoat_normal);
    if (chain_bsdf.is_black()) break;
    float u_lobe;
    glm::vec2 u_dir;
    sampler.get_chain(vertex, v - vertex, &u_lobe, &u_dir);
    BsdfSample bs;
    if (!chain_bsdf.sample(u_lobe, u_dir, &bs) || !bs.delta) break;
    if (p.transmission > 0.0f && p.metallic < 1.0f) *through_glass = true;
    t *= bs.weight;
    ray.origin = offset_ray_origin(q.position, q.geometric_normal, bs.wi);
    ray.direction = bs.wi;
  }
  return light;
}

}  // namespace pxf
