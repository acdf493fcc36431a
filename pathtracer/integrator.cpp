#include "pathtracer/integrator.h"

#include <algorithm>
#include <cmath>

#include "pathtracer/bsdf.h"
#include "pathtracer/rng.h"

namespace pxf {
namespace {

constexpr int kMaxSpecularChainBounces = 8;

struct PathState {
  glm::vec3 throughput{1.0f};
  int nonspecular = 0;     // non-delta interactions so far
  bool prev_delta = true;  // the last interaction was a delta lobe (or the camera)
  float prev_pdf = 0.0f;   // solid-angle pdf of the last non-delta BSDF sample
};

// The path so far is E S* (emission here is E S* L), or E S* D with the D just before (E S* D L).
bool emission_is_lv(const PathState& s) { return s.nonspecular == 0 || (s.nonspecular == 1 && !s.prev_delta); }

void add_contribution(PathSample& out, glm::vec3 value, bool lv, bool all_hv) {
  if (lv && !all_hv)
    out.lv += value;
  else
    out.hv += value;
}

}  // namespace

bool PathSample::finite() const { return is_finite(lv) && is_finite(hv); }

PathTracer::PathTracer(const Scene& scene) : geometry_(scene), lights_(scene) {
  for (const Mesh& mesh : scene.meshes)
    if (!mesh.triangles.empty() && material_is_perfect_specular(scene.materials[mesh.material]))
      has_perfect_specular_ = true;
}

PathSample PathTracer::trace_pixel(const Camera& camera, int width, int height, int x, int y, uint32_t frame,
                                   const TraceParams& params) const {
  uint64_t pixel = static_cast<uint64_t>(y) * static_cast<uint64_t>(width) + static_cast<uint64_t>(x);
  Rng rng(params.seed, pixel, frame);
  glm::vec2 jitter = rng.next_2d();  // box filter: uniform in the pixel
  Ray ray = camera_ray(camera, width, height, static_cast<float>(x) + jitter.x, static_cast<float>(y) + jitter.y);
  return trace_ray(ray, pixel, frame, params);
}

PathSample PathTracer::trace_ray(const Ray& camera_ray, uint64_t pixel_index, uint32_t frame,
                                 const TraceParams& params) const {
  // A second stream for the path itself (the pixel stream's first draws went to the jitter).
  Rng rng(params.seed ^ 0x5bd1e9955bd1e995ULL, pixel_index, frame);
  const Scene& scene = geometry_.scene();
  PathSample out;
  PathState s;
  Ray ray = camera_ray;
  for (int vertex = 2; vertex <= params.max_vertices; ++vertex) {
    Hit hit = geometry_.intersect(ray);
    ++out.rays;
    if (!hit.valid()) {  // the environment is the light vertex
      if (lights_.has_environment()) {
        float w = s.prev_delta ? 1.0f : power_heuristic(s.prev_pdf, lights_.pdf_environment(ray.direction));
        add_contribution(out, s.throughput * lights_.environment_radiance(ray.direction) * w, emission_is_lv(s),
                         params.all_hv);
      }
      break;
    }
    SurfacePoint sp = geometry_.surface_point(hit, ray);
    const Material& material = *sp.material;
    if (material.is_emissive() && (sp.front_face || material.double_sided)) {
      float w = 1.0f;
      if (!s.prev_delta)
        w = power_heuristic(s.prev_pdf, lights_.pdf_triangle(hit.mesh, hit.prim, ray.origin, sp.position, sp.geometric_normal));
      add_contribution(out, s.throughput * eval_emission(scene, material, sp.uv0, sp.uv1) * w, emission_is_lv(s),
                       params.all_hv);
    }
    if (vertex == params.max_vertices) break;  // no room for another vertex

    glm::vec3 wo = -ray.direction;
    Bsdf bsdf(eval_material(scene, material, sp.uv0, sp.uv1, sp.color), sp.shading_normal, sp.geometric_normal, wo,
              sp.front_face);
    if (bsdf.is_black()) break;

    // Next event estimation (the light vertex is vertex + 1 <= max_vertices).
    float u_light = rng.next_float();
    glm::vec2 u_light2 = rng.next_2d();
    if (bsdf.has_nondelta()) {
      LightSample ls;
      if (lights_.sample(sp.position, u_light, u_light2, &ls)) {
        float bsdf_pdf;
        glm::vec3 f = bsdf.eval(ls.wi, &bsdf_pdf);
        if (max_component(f) > 0.0f && max_component(ls.radiance) > 0.0f) {
          glm::vec3 origin = offset_ray_origin(sp.position, sp.geometric_normal, ls.wi);
          float tmax = std::isinf(ls.distance) ? ls.distance : ls.distance * (1.0f - 1e-3f);
          ++out.rays;
          if (!geometry_.occluded(origin, ls.wi, tmax)) {
            float w = ls.delta ? 1.0f : power_heuristic(ls.pdf, bsdf_pdf);
            add_contribution(out, s.throughput * f * ls.radiance * (w / ls.pdf), s.nonspecular == 0, params.all_hv);
          }
        }
      }
    }

    // Continue the path by sampling the BSDF.
    float u_lobe = rng.next_float();
    glm::vec2 u_dir = rng.next_2d();
    float u_rr = rng.next_float();
    BsdfSample bs;
    if (!bsdf.sample(u_lobe, u_dir, &bs)) break;
    s.throughput *= bs.weight;
    if (!bs.delta) ++s.nonspecular;
    s.prev_delta = bs.delta;
    s.prev_pdf = bs.pdf;
    if (vertex >= params.rr_start_vertex) {
      float q = std::min(1.0f, max_component(s.throughput));
      if (!(u_rr < q)) break;
      s.throughput /= q;
    }
    ray.origin = offset_ray_origin(sp.position, sp.geometric_normal, bs.wi);
    ray.direction = bs.wi;
  }
  return out;
}

SpecularChainHit PathTracer::trace_specular_chain(const Ray& camera_ray) const {
  const Scene& scene = geometry_.scene();
  SpecularChainHit result;
  glm::vec3 tint(1.0f);
  Ray ray = camera_ray;
  for (int bounce = 0; bounce <= kMaxSpecularChainBounces; ++bounce) {
    Hit hit = geometry_.intersect(ray);
    if (!hit.valid()) {
      result.range_color = range_environment_color(tint * lights_.environment_radiance(ray.direction));
      return result;
    }
    SurfacePoint sp = geometry_.surface_point(hit, ray);
    result.distance += hit.t;
    const Material& material = *sp.material;
    BsdfParams p = eval_material(scene, material, sp.uv0, sp.uv1, sp.color);
    glm::vec3 wo = -ray.direction;
    if (!material_is_perfect_specular(material) || bounce == kMaxSpecularChainBounces) {
      glm::vec3 n = sp.vertex_normal;
      if (material.double_sided && glm::dot(n, wo) < 0.0f) n = -n;
      result.range_color = range_shading(p.base_color * tint, n, wo);
      result.hit = true;
      return result;
    }
    tint *= p.base_color;
    glm::vec3 ng = sp.front_face ? sp.geometric_normal : -sp.geometric_normal;  // on wo's side
    glm::vec3 n = glm::dot(sp.shading_normal, ng) >= 0.0f ? sp.shading_normal : -sp.shading_normal;
    float cos_i = glm::dot(wo, n);
    if (cos_i <= 1e-4f) {
      n = ng;
      cos_i = glm::dot(wo, n);
    }
    glm::vec3 wi = glm::reflect(ray.direction, n);
    if (!material_is_perfect_mirror(material)) {  // glass: the transmitted branch unless TIR
      float eta = sp.front_face ? p.ior : 1.0f / p.ior;
      float sin2_t = (1.0f - cos_i * cos_i) / (eta * eta);
      if (sin2_t < 1.0f) wi = glm::normalize(-wo / eta + (cos_i / eta - std::sqrt(1.0f - sin2_t)) * n);
    }
    ray.origin = offset_ray_origin(sp.position, sp.geometric_normal, wi);
    ray.direction = wi;
  }
  return result;
}

void resize_accumulation(Accumulation& acc, int width, int height) {
  size_t n = static_cast<size_t>(width) * static_cast<size_t>(height);
  acc.width = width;
  acc.height = height;
  acc.lv_mean.assign(n, glm::vec3(0.0f));
  acc.hv_mean.assign(n, glm::vec3(0.0f));
  acc.hv_lum_mean.assign(n, 0.0);
  acc.hv_lum_m2.assign(n, 0.0);
  acc.samples.assign(n, 0u);
}

void accumulate_sample(Accumulation& acc, size_t pixel, glm::vec3 lv, glm::vec3 hv) {
  uint32_t n = ++acc.samples[pixel];
  float inv_n = 1.0f / static_cast<float>(n);
  acc.lv_mean[pixel] += (lv - acc.lv_mean[pixel]) * inv_n;
  acc.hv_mean[pixel] += (hv - acc.hv_mean[pixel]) * inv_n;
  double y = luminance(hv);
  double delta = y - acc.hv_lum_mean[pixel];
  acc.hv_lum_mean[pixel] += delta / static_cast<double>(n);
  acc.hv_lum_m2[pixel] += delta * (y - acc.hv_lum_mean[pixel]);
}

float Accumulation::variance_of_mean(size_t pixel) const {
  uint32_t n = samples[pixel];
  if (n < 2) return -1.0f;
  double var = hv_lum_m2[pixel] / static_cast<double>(n - 1) / static_cast<double>(n);
  return static_cast<float>(std::max(0.0, var));
}

}  // namespace pxf
