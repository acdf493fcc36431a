#include "pathtracer/integrator.h"

#include <algorithm>
#include <limits>
#include <cmath>
#include <utility>

#include "pathtracer/bsdf.h"
#include "pathtracer/guiding_field.h"
#include "pathtracer/guiding_mixture.h"
#include "pathtracer/sampler.h"

#include <tbb/parallel_for.h>

namespace pxf {
namespace {

constexpr int kMaxSpecularChainBounces = 8;
// Paths traced together; a 16 x 16 tile of the progressive renderer is one batch. The batch state
// lives on the stack (about 45 KB).
constexpr int kBatchPaths = 256;
// Path guiding: the surfaces of a training photon's path that can record (the key's room per photon).
constexpr int kMaxPhotonSurfaces = 16;

struct PathState {
  glm::vec3 throughput{1.0f};
  int nonspecular = 0;     // non-delta interactions so far
  bool prev_delta = true;  // the last interaction was a delta lobe (or the camera)
  float prev_pdf = 0.0f;   // solid-angle pdf of the last non-delta BSDF sample
  glm::vec3 prev_position{0.0f};  // the surface point the ray left (un-offset: the light pdf's origin)
  bool albedo_set = false;        // PathSample::albedo holds the first non-delta vertex's albedo
  // Specular sampling: the MIS weight of light found after the last non-delta sample through a
  // chain of perfectly specular surfaces (D S+ L), against the specular strategy; 1 without it.
  float chain_mis = 1.0f;
  // Russian roulette's view of the throughput: what it would be had every guided vertex sampled
  // its BSDF alone (the product of p_mixture / p_bsdf over them; 1 without guiding). A guided
  // direction toward bright light has a small weight f / p_mixture; rouletting on that weight
  // would kill most such paths and give the survivors back the weight guiding took away.
  float roulette_scale = 1.0f;
  // What the last non-delta vertex's region learned of the visible sky: an escaped ray's MIS
  // weight needs the pdf NEE had there.
  VisibleSky prev_sky;
  // Texture footprints (ray cones): the angle the path's footprint has spread by since its
  // first rough bounce, and its world-space width at the current vertex. Both stay 0 up to the
  // first non-delta bounce, so what the camera sees, directly or through mirrors and glass, reads
  // the textures' finest level.
  float cone_spread = 0.0f;
  float cone_width = 0.0f;
};

// A non-delta sample with solid-angle pdf p stands for a lobe about 1/sqrt(p) radians wide; the
// cone after it spreads by this share of that width. 1/16: a diffuse bounce (about 0.1 rad) makes a
// texture 3 m away read texels 30 cm wide, which a hemisphere's worth of light averages anyway,
// while a glossy lobe of GGX alpha 0.05 keeps detail of about a centimetre (docs/sampling.md,
// "Texture footprints", measures the bias and the speed).
constexpr float kFootprintLobeShare = 1.0f / 16.0f;

float footprint_spread(float pdf) { return pdf > 0.0f ? kFootprintLobeShare / std::sqrt(pdf) : 0.0f; }

// The factor from a guided vertex's weight f / p_mixture to BSDF sampling's f / p_bsdf, for
// PathState::roulette_scale; bounded so that the scale stays finite (any factor keeps roulette unbiased).
float unguided_weight_ratio(float mixture_pdf, float bsdf_pdf) {
  return bsdf_pdf > 0.0f ? std::min(mixture_pdf / bsdf_pdf, 1e6f) : 1e6f;
}

// The path so far is E S* (emission here is E S* L), or E S* D with the D just before (E S* D L).
bool emission_is_lv(const PathState& s) { return s.nonspecular == 0 || (s.nonspecular == 1 && !s.prev_delta); }

// Where emission reached along the path goes. Light the camera sees directly or through perfectly
// specular chains (E S* L: nothing sampled but the pixel position) stays in LV, so that an
// environment seen as the backdrop is not filtered into, or blurred with, the objects before it.
// The environment's light at the first surface goes to HV: a large light of high dynamic range, often
// partly hidden, seen through glossy lobes, it is where an object under a sky keeps its noise
// (docs/method.md 1.1). all_hv moves the emitters' there too.
bool emission_goes_to_lv(const PathState& s, bool environment, bool all_hv) {
  return emission_is_lv(s) && ((!all_hv && !environment) || s.nonspecular == 0);
}

void add_contribution(PathSample& out, glm::vec3 value, bool lv) {
  if (lv)
    out.lv += value;
  else
    out.hv += value;
}

// Adds an HV contribution to a sample's classification: the largest one names the sample's class.
void record_hv(HvSampleClass& sample, glm::vec3 value, HvClass c) {
  const float y = luminance(value);
  if (sample.dominant == HvClass::None || y > sample.dominant_luminance) {
    sample.dominant = c;
    sample.dominant_luminance = y;
  }
}

}  // namespace

const char* hv_class_name(HvClass c) {
  switch (c) {
    case HvClass::None: return "none";
    case HvClass::EmitterBackFace: return "emitter back face";
    case HvClass::GlassInternal: return "glass internal reflection";
    case HvClass::CausticGlass: return "caustic through glass (D S+ L)";
    case HvClass::CausticMirror: return "caustic via mirror (D S+ L)";
    case HvClass::SpecularBetweenDiffuse: return "specular between diffuse (D S+ D)";
    case HvClass::SeenThroughSpecular: return "seen through specular (E S+ D)";
    case HvClass::Diffuse: return "diffuse interreflection";
    case HvClass::Count: break;
  }
  return "?";
}

// What the firefly attribution knows of a path so far (HvClass); only trace_pixels_classified keeps it.
struct PathTracer::ClassState {
  HvSampleClass* out = nullptr;
  bool emitter_back_face = false;  // scattered off an emitter's back face
  bool glass_internal = false;     // a delta reflection inside glass
  bool glass_since_d = false;      // delta interactions with glass / mirrors since the last D vertex
  bool mirror_since_d = false;
  bool specular_between_d = false;  // a D S+ D stretch
  bool specular_before_d = false;   // delta interactions before the first D vertex

  // The class of light reaching the path now: through the BSDF sample that just arrived
  // (`by_bsdf`: a specular chain since the last D is a caustic), or by NEE at a D vertex.
  HvClass classify(int nonspecular, bool by_bsdf) const {
    const bool chain = glass_since_d || mirror_since_d;
    if (emitter_back_face) return HvClass::EmitterBackFace;
    if (glass_internal) return HvClass::GlassInternal;
    if (by_bsdf && nonspecular > 0 && chain) return glass_since_d ? HvClass::CausticGlass : HvClass::CausticMirror;
    if (specular_between_d || (!by_bsdf && nonspecular > 0 && chain)) return HvClass::SpecularBetweenDiffuse;
    if (specular_before_d) return HvClass::SeenThroughSpecular;
    return HvClass::Diffuse;
  }
};

// One path of a batch: its random stream, the ray it traces next, and what it has gathered.
struct PathTracer::Path {
  PathSampler sampler;
  Ray ray;
  PathState state;
  PathSample* out = nullptr;
};

// The next event estimation contributions of one vertex step of a batch, each waiting on its
// shadow ray. Resolving them before the next step keeps every path's sum in the order of a path
// traced alone (emission at vertex k, light at vertex k, emission at vertex k + 1, ...).
struct PathTracer::ShadowQueue {
  struct Pending {
    PathSample* out;
    glm::vec3 contribution;  // added when the shadow ray reaches the light
    bool lv;
    // An environment sample: recorded in this region of the visibility field when unblocked.
    uint32_t sky_region = EnvironmentVisibility::kNoRegion;
    float sky_value = 0.0f;  // luminance / pdf
  };
  // Per path and vertex: the chosen light's shadow ray and one per fixed light.
  static constexpr size_t kCapacity = kBatchPaths * (1 + LightSampler::kMaxFixedLights);
  ShadowRay rays[kCapacity];
  Pending pending[kCapacity];
  bool occluded[kCapacity];
  // Firefly attribution only (trace_pixels_classified): each pending contribution's sample and class.
  HvSampleClass* class_out[kCapacity];
  HvClass classes[kCapacity];
  int count = 0;

  void push(const ShadowRay& ray, const Pending& contribution) {
    rays[count] = ray;
    pending[count] = contribution;
    ++count;
  }
  template <bool kClassify>
  void resolve(const EmbreeScene& geometry, EnvironmentVisibility* visibility) {
    geometry.occluded(rays, static_cast<size_t>(count), occluded);
    for (int i = 0; i < count; ++i) {
      if (pending[i].sky_region != EnvironmentVisibility::kNoRegion)
        visibility->record(pending[i].sky_region, rays[i].direction, pending[i].sky_value, !occluded[i], true);
      if (!occluded[i]) {
        const bool lv = pending[i].lv;
        add_contribution(*pending[i].out, pending[i].contribution, lv);
        if constexpr (kClassify)
          if (!lv) record_hv(*class_out[i], pending[i].contribution, classes[i]);
      }
    }
    count = 0;
  }
};

// A surface vertex of a path as shade_vertex's parts see it: the point, its material's parameters,
// its BSDF, the BSDF-side strategy (guiding_mixture) and the vertex's index.
struct PathTracer::Vertex {
  const SurfacePoint& sp;
  const BsdfParams& params;
  const Bsdf& bsdf;
  GuidingMixture mixture;
  int index;
  VisibleSky sky;  // the vertex's region of the visibility field, and what it learned
};

bool PathSample::finite() const { return is_finite(lv) && is_finite(hv); }

PathTracer::PathTracer(const Scene& scene)
    : geometry_(scene), lights_(scene), materials_(scene), chains_(geometry_, lights_, materials_) {}

PathSample PathTracer::trace_pixel(const Camera& camera, int width, int height, int x, int y, uint32_t frame,
                                   const TraceParams& params) const {
  PathSample out;
  trace_pixels(camera, width, height, PixelRect{x, y, x + 1, y + 1}, frame, params, &out);
  return out;
}

namespace {
// The jobs of pixels first .. first + count - 1 (row-major in rect), all at sample index `frame`.
void rect_jobs(const PixelRect& rect, int first, int count, uint32_t frame, PixelSampleJob* jobs) {
  for (int i = 0; i < count; ++i)
    jobs[i] = PixelSampleJob{rect.x0 + (first + i) % rect.width(), rect.y0 + (first + i) / rect.width(), frame};
}
}  // namespace

void PathTracer::trace_pixels(const Camera& camera, int width, int height, const PixelRect& rect, uint32_t frame,
                              const TraceParams& params, PathSample* out) const {
  const int count = rect.count();
  PixelSampleJob jobs[kBatchPaths];
  for (int first = 0; first < count; first += kBatchPaths) {
    const int batch = std::min(kBatchPaths, count - first);
    rect_jobs(rect, first, batch, frame, jobs);
    trace_batch<false>(camera, width, height, jobs, batch, params, out + first, nullptr);
  }
}

void PathTracer::trace_jobs(const Camera& camera, int width, int height, const PixelSampleJob* jobs, int count,
                            const TraceParams& params, PathSample* out) const {
  for (int first = 0; first < count; first += kBatchPaths)
    trace_batch<false>(camera, width, height, jobs + first, std::min(kBatchPaths, count - first), params, out + first,
                       nullptr);
}

void PathTracer::trace_pixels_classified(const Camera& camera, int width, int height, const PixelRect& rect,
                                         uint32_t frame, const TraceParams& params, PathSample* out,
                                         HvSampleClass* classes) const {
  const int count = rect.count();
  PixelSampleJob jobs[kBatchPaths];
  for (int first = 0; first < count; first += kBatchPaths) {
    const int batch = std::min(kBatchPaths, count - first);
    rect_jobs(rect, first, batch, frame, jobs);
    trace_batch<true>(camera, width, height, jobs, batch, params, out + first, classes + first);
  }
}

// The paths of jobs[0 .. count - 1], in lockstep.
template <bool kClassify>
void PathTracer::trace_batch(const Camera& camera, int width, int height, const PixelSampleJob* jobs, int count,
                             const TraceParams& params, PathSample* out, HvSampleClass* classes) const {
  const CameraRays camera_rays(camera, width, height);
  Path paths[kBatchPaths];
  ClassState class_states[kClassify ? kBatchPaths : 1];
  if constexpr (kClassify)
    for (int i = 0; i < count; ++i) {
      classes[i] = HvSampleClass{};
      class_states[i] = ClassState{};
      class_states[i].out = &classes[i];
    }
  // Three passes over the batch, each a loop of independent iterations: the samplers' key hashes,
  // then the jitters, then the camera rays. In one loop each path's chain of dependent hashes
  // stalled the next; apart, the processor overlaps many paths' hashes.
  glm::vec2 jitters[kBatchPaths];
  // What the sampler derives from the sample index alone, recomputed only where the index changes
  // (a uniform frame's batch has one index).
  FrameSampling frame_sampling(params.seed, jobs[0].index, params.replicates);
  for (int i = 0; i < count; ++i) {
    if (jobs[i].index != frame_sampling.frame) frame_sampling = FrameSampling(params.seed, jobs[i].index, params.replicates);
    const uint64_t pixel = static_cast<uint64_t>(jobs[i].y) * static_cast<uint64_t>(width) + static_cast<uint64_t>(jobs[i].x);
    paths[i].sampler = PathSampler(params.sampler, frame_sampling, pixel);
  }
  for (int i = 0; i < count; ++i) jitters[i] = paths[i].sampler.camera_jitter();  // box filter: uniform in the pixel
  for (int i = 0; i < count; ++i) {
    out[i] = PathSample{};
    Path& path = paths[i];
    path.ray = camera_rays(static_cast<float>(jobs[i].x) + jitters[i].x, static_cast<float>(jobs[i].y) + jitters[i].y);
    path.state = PathState{};
    path.out = &out[i];
  }
  // live[k] is the k-th path still being traced; rays[k] and hits[k] are its ray and hit.
  int live[kBatchPaths];
  int live_count = count;
  for (int i = 0; i < count; ++i) live[i] = i;
  Ray rays[kBatchPaths];
  Hit hits[kBatchPaths];
  PathSampler::VertexNumbers numbers[kBatchPaths];
  ShadowQueue shadows;
  for (int vertex = 2; vertex <= params.max_vertices && live_count > 0; ++vertex) {
    for (int k = 0; k < live_count; ++k) rays[k] = paths[live[k]].ray;
    geometry_.intersect(rays, static_cast<size_t>(live_count),
                        vertex == 2 ? RayCoherence::Coherent : RayCoherence::Incoherent, hits);
    // The Sobol numbers of this vertex for every path still in QMC, before any is shaded (see
    // PathSampler::vertex_numbers).
    const bool roulette = vertex >= params.rr_start_vertex;
    for (int k = 0; k < live_count; ++k)
      if (paths[live[k]].sampler.in_qmc()) numbers[k] = paths[live[k]].sampler.vertex_numbers(vertex, roulette);
    int still_live = 0;
    for (int k = 0; k < live_count; ++k)
      if (shade_vertex<kClassify>(paths[live[k]], hits[k], vertex, params, shadows,
                                  paths[live[k]].sampler.in_qmc() ? &numbers[k] : nullptr,
                                  kClassify ? &class_states[live[k]] : nullptr))
        live[still_live++] = live[k];
    live_count = still_live;
    shadows.resolve<kClassify>(geometry_, visibility_);
  }
}

void PathTracer::trace_guiding_photons(uint32_t frame, int count, const TraceParams& params) const {
  if (!guiding_ || count <= 0 || lights_.empty()) return;
  tbb::parallel_for(tbb::blocked_range<int>(0, count, 64), [&](const tbb::blocked_range<int>& range) {
    for (int i = range.begin(); i != range.end(); ++i)
      trace_guiding_photon(frame, static_cast<uint32_t>(i), params);
  });
}

namespace {

// The companion of a photon (below) leaves the chain's source this many radians off the photon's
// direction, or, from a light at infinity, this far beside it per unit of the first segment's length.
constexpr float kCompanionSpread = 2e-3f;

// A unit vector at kCompanionSpread radians from the unit vector d.
glm::vec3 turned(const glm::vec3& d) {
  const glm::vec3 side = std::abs(d.x) < 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
  return glm::normalize(d + kCompanionSpread * glm::normalize(glm::cross(d, side)));
}

// Where along the line (p, unit u) it passes closest to the line (q, unit v); 0 when they are parallel.
float closest_approach(const glm::vec3& p, const glm::vec3& u, const glm::vec3& q, const glm::vec3& v) {
  const glm::dvec3 w(p - q);
  const double b = glm::dot(glm::dvec3(u), glm::dvec3(v));
  const double denom = 1.0 - b * b;
  if (!(denom > 1e-12)) return 0.0f;
  const double d = glm::dot(glm::dvec3(u), w), e = glm::dot(glm::dvec3(v), w);
  return static_cast<float>((b * e - d) / denom);
}

}  // namespace

// One photon: the flux it carries is recorded (key: frame, photon, bounce) at its non-delta
// surfaces from the second on, then it scatters by BSDF sampling (the BSDF is treated as
// symmetric: the shading-normal correction of adjoint transport only changes the guide's
// weights, never an image's expectation) with Russian roulette on its share of the emitted flux.
//
// Each record says where its light seems to come from, for the field's parallax lobes: the previous
// vertex, unless delta bounces came between. Then a companion ray leaves the chain's source (the last
// non-delta vertex or the emission point) turned by kCompanionSpread (parallel and beside the photon
// from a light at infinity) and takes the same delta bounces; where the two rays' lines pass closest
// is the light's apparent source at the record (its image in a curved mirror, ahead of it where the
// rays converge to a focus). Without that, a caustic's source would be its point on the mirror, which
// moves with the receiving point.
void PathTracer::trace_guiding_photon(uint32_t frame, uint32_t index, const TraceParams& params) const {
  constexpr uint64_t kPhotonStream = 0x70686f746f6e73ULL;  // apart from every camera path's stream
  Rng rng(params.seed ^ kPhotonStream, index, frame);
  EmittedPhoton photon;
  const glm::vec2 u_select = rng.next_2d(), u_position = rng.next_2d(), u_direction = rng.next_2d();
  if (!lights_.sample_emission(u_select, u_position, u_direction, &photon)) return;
  const float emitted = max_component(photon.flux);
  Ray ray{photon.origin, photon.direction};
  glm::vec3 flux = photon.flux;
  const uint64_t key = (static_cast<uint64_t>(frame) << 36) | (static_cast<uint64_t>(index) << 4);  // + surface < 16
  const int max_surfaces = std::min(params.max_vertices - 1, kMaxPhotonSurfaces);
  const auto bsdf_at = [&](const SurfacePoint& sp, const glm::vec3& wo, BsdfMaterial* scratch) {
    return Bsdf(materials_.at(sp, scratch), sp.shading_normal, sp.geometric_normal, wo, sp.front_face, sp.clearcoat_normal);
  };
  Ray chain_start = ray;  // the segment that left the chain's source
  bool chain_from_infinity = photon.from_infinity, chain_has_delta = false;
  enum class CompanionState { kNone, kActive, kLost } companion = CompanionState::kNone;
  Ray companion_ray;
  SurfacePoint companion_sp;
  // The companion's next surface, which must be the photon's (the same material), else it is lost.
  const auto advance_companion = [&](const SurfacePoint& sp) {
    const Hit hit = geometry_.intersect(companion_ray);
    if (!hit.valid()) return false;
    companion_sp = geometry_.surface_point(hit, companion_ray);
    return companion_sp.material == sp.material && companion_sp.front_face == sp.front_face;
  };
  for (int surface = 0; surface < max_surfaces; ++surface) {
    const Hit hit = geometry_.intersect(ray);
    if (!hit.valid()) return;
    const SurfacePoint sp = geometry_.surface_point(hit, ray);
    if (!sp.front_face && sp.material->has_volume()) flux *= volume_transmittance(*sp.material, hit.t);
    if (companion == CompanionState::kActive && !advance_companion(sp)) companion = CompanionState::kLost;
    BsdfMaterial scratch;
    const Bsdf bsdf = bsdf_at(sp, -ray.direction, &scratch);
    if (bsdf.is_black()) return;
    if (surface > 0 && bsdf.has_nondelta()) {
      float distance = hit.t * glm::length(ray.direction);
      if (chain_has_delta && companion == CompanionState::kActive) {
        distance = closest_approach(sp.position, -ray.direction, companion_sp.position, -companion_ray.direction);
      }
      const glm::vec3 n = glm::dot(sp.geometric_normal, ray.direction) < 0.0f ? sp.geometric_normal : -sp.geometric_normal;
      guiding_->record(key + static_cast<uint64_t>(surface), sp.position, -ray.direction, luminance(flux), 1.0f, distance, n,
                       chain_has_delta);
    }
    BsdfSample bs;
    const float u_lobe = rng.next_float();
    const glm::vec2 u_bsdf = rng.next_2d();
    if (!bsdf.sample(u_lobe, u_bsdf, &bs)) return;
    if (bs.delta && companion != CompanionState::kLost) {
      if (companion == CompanionState::kNone) {  // the first delta bounce of the chain: catch up
        const float beside = kCompanionSpread * (1.0f + hit.t);
        companion_ray = chain_from_infinity
                            ? Ray{chain_start.origin + beside * glm::normalize(glm::cross(chain_start.direction, turned(chain_start.direction))), chain_start.direction}
                            : Ray{chain_start.origin, turned(chain_start.direction)};
        companion = advance_companion(sp) ? CompanionState::kActive : CompanionState::kLost;
      }
      BsdfMaterial companion_scratch;
      BsdfSample cs;
      if (companion == CompanionState::kActive &&
          bsdf_at(companion_sp, -companion_ray.direction, &companion_scratch).sample(u_lobe, u_bsdf, &cs) && cs.delta &&
          cs.transmitted == bs.transmitted) {
        companion_ray = Ray{offset_ray_origin(companion_sp.position, companion_sp.geometric_normal, cs.wi), cs.wi};
      } else {
        companion = CompanionState::kLost;
      }
    }
    flux *= bs.weight;
    const float survive = std::min(1.0f, max_component(flux) / emitted);
    if (!(rng.next_float() < survive)) return;
    flux /= survive;
    ray = Ray{offset_ray_origin(sp.position, sp.geometric_normal, bs.wi), bs.wi};
    if (bs.delta) {
      chain_has_delta = true;
    } else {  // a new chain starts here, from this point
      chain_start = ray;
      chain_from_infinity = chain_has_delta = false;
      companion = CompanionState::kNone;
    }
  }
}

// Vertex `vertex` of a path at `hit`: the emission found there, next event estimation (queued on
// `shadows`), the light of a specular chain, and the BSDF sample that continues the path into
// path.ray. False: the path ends here.
// kClassify: the firefly attribution's instrumentation (trace_pixels_classified, tests only). It
// stays inline, in `if constexpr` blocks, because the attribution must see exactly the decisions a
// render makes, and a second shading function would drift from this one; the blocks compile away
// in the renders' instantiation (kClassify false).
template <bool kClassify>
bool PathTracer::shade_vertex(Path& path, const Hit& hit, int vertex, const TraceParams& params, ShadowQueue& shadows,
                              const PathSampler::VertexNumbers* numbers, [[maybe_unused]] ClassState* cls) const {
  const Scene& scene = geometry_.scene();
  PathState& s = path.state;
  PathSample& out = *path.out;
  PathSampler& sampler = path.sampler;
  ++out.rays;
  if (!hit.valid()) {  // the environment is the light vertex
    if (lights_.has_environment()) {
      float light_pdf;
      const glm::vec3 radiance = lights_.environment_hit(path.ray.direction, &s.prev_sky, &light_pdf);
      float w = s.prev_delta ? s.chain_mis : power_heuristic(s.prev_pdf, light_pdf);
      const glm::vec3 value = s.throughput * radiance * w;
      // The sky seen through the BSDF's sample teaches the last vertex's region as NEE's does.
      if (s.prev_sky.region() != EnvironmentVisibility::kNoRegion && !s.prev_delta && visibility_->learning())
        visibility_->record(s.prev_sky.region(), path.ray.direction, luminance(radiance) / s.prev_pdf, true, false);
      const bool lv = emission_goes_to_lv(s, true, params.all_hv);
      add_contribution(out, value, lv);
      if constexpr (kClassify)
        if (!lv) record_hv(*cls->out, value, cls->classify(s.nonspecular, true));
    }
    return false;
  }
  s.cone_width += s.cone_spread * hit.t;
  SurfacePoint sp = geometry_.surface_point(hit, path.ray, s.cone_width);
  const Material& material = *sp.material;
  // Reaching a back face of an absorbing medium's boundary: the segment just traced ran inside it.
  if (!sp.front_face && material.has_volume()) s.throughput *= volume_transmittance(material, hit.t);
  if (emission_visible(material, sp)) {
    float w = s.chain_mis;  // 1 unless specular sampling could have found this light (D S+ L)
    if (!s.prev_delta)
      w = power_heuristic(s.prev_pdf,
                          lights_.pdf_triangle(hit.mesh, hit.prim, s.prev_position, sp.position, sp.geometric_normal));
    const glm::vec3 value = s.throughput * eval_emission(scene, material, sp.uv0, sp.uv1) * w;
    const bool lv = emission_goes_to_lv(s, false, params.all_hv);
    add_contribution(out, value, lv);
    if constexpr (kClassify)
      if (!lv) record_hv(*cls->out, value, cls->classify(s.nonspecular, true));
  }
  if constexpr (kClassify)
    if (material.is_emissive() && !emission_visible(material, sp)) cls->emitter_back_face = true;
  const bool last_vertex = vertex == params.max_vertices;  // no room for another vertex
  if (last_vertex && s.albedo_set) return false;

  glm::vec3 wo = -path.ray.direction;
  BsdfMaterial scratch;
  const BsdfMaterial& lobes = materials_.at(sp, &scratch);
  const BsdfParams& bsdf_params = lobes.params;
  Bsdf bsdf(lobes, sp.shading_normal, sp.geometric_normal, wo, sp.front_face, sp.clearcoat_normal);
  if (!s.albedo_set && (bsdf.has_nondelta() || bsdf.is_black())) {
    out.albedo = bsdf.nondelta_albedo();
    s.albedo_set = true;
  }
  if (last_vertex || bsdf.is_black()) return false;

  const uint32_t sky_region = visibility_ && bsdf.has_nondelta()
                                  ? visibility_->region(sp.position, glm::dot(sp.geometric_normal, wo) >= 0.0f
                                                                        ? sp.geometric_normal
                                                                        : -sp.geometric_normal)
                                  : EnvironmentVisibility::kNoRegion;
  const Vertex v{sp, bsdf_params, bsdf, guiding_mixture(sp, bsdf, wo, params), vertex,
                 visibility_ ? visibility_->sky(sky_region) : VisibleSky{}};
  // Next event estimation (the light vertex is vertex + 1 <= max_vertices).
  const PathSampler::LightNumbers u_light = numbers ? numbers->light : sampler.light_numbers(vertex, bsdf.has_nondelta());
  if (bsdf.has_nondelta()) sample_direct_light<kClassify>(path, v, u_light, params.all_hv, shadows, cls);
  // Light through a specular chain, which NEE cannot reach (HV: D S+ L).
  const bool room = chains_.traces_any(params) && bsdf.has_nondelta() && vertex + 2 <= params.max_vertices;
  const SpecularChainSampler::Plan plan = room ? chains_.plan(sp.position, params, s.nonspecular == 0)
                                               : SpecularChainSampler::Plan{};
  if (plan.traces()) add_chain_light<kClassify>(path, v, plan, params, cls);
  return continue_path<kClassify>(path, v, plan, params, numbers, cls);
}

// Path guiding: once the field is trained, the BSDF-side strategy of every non-delta vertex is the
// mixture that takes the guided direction with probability alpha (times the BSDF's diffuse share:
// the field knows the incident light, not the BSDF, so it serves a diffuse lobe; glossy and delta
// lobes keep their samples). Every vertex, not the first alone: in a room lit through a window
// most of the first vertex's variance is its deeper vertices' (0.83 of it, `pxf bench
// guiding-bound --scene window`), and guiding them all took the window's display error at equal
// samples from 30.4 % to 25.3 % (docs/guiding.md). A leaf that learned no light (a uniform
// distribution), or only light behind the surface or too wide to guide, is not guided, and alpha
// is scaled by the learned light's share the point's distribution holds.
GuidingMixture PathTracer::guiding_mixture(const SurfacePoint& sp, const Bsdf& bsdf, glm::vec3 wo,
                                           const TraceParams& params) const {
  GuidingMixture mixture;
  if (guiding_ && params.guiding != GuidingMode::Off && bsdf.has_nondelta() && guiding_->trained()) {
    const glm::vec3 n = sp.geometric_normal;
    mixture.guide = guiding_->distribution(sp.position, glm::dot(n, wo) >= 0.0f ? n : -n);
    mixture.guided = mixture.guide.learned();
    mixture.alpha = mixture.guide.alpha() * bsdf.diffuse_probability() * mixture.guide.share();
  }
  return mixture;
}

// Next event estimation at a non-delta vertex: the light sample of the chosen light, then every
// fixed light's (LightSampler::kMaxFixedLights), each queued on `shadows` with its MIS weight. At the
// first non-delta vertex a fixed light's contribution is exact (nothing random decides it), so it
// goes to LV; the chosen light's goes there too unless it is the environment's or all_hv is on
// (emission_goes_to_lv: sampling made it noisy).
template <bool kClassify>
void PathTracer::sample_direct_light(Path& path, const Vertex& v, const PathSampler::LightNumbers& u_light, bool all_hv,
                                     ShadowQueue& shadows, [[maybe_unused]] ClassState* cls) const {
  const PathState& s = path.state;
  PathSample& out = *path.out;
  const SurfacePoint& sp = v.sp;
  const auto queue_light = [&](const LightSample& ls, bool exact) {
    float bsdf_pdf;
    glm::vec3 f = v.bsdf.eval(ls.wi, &bsdf_pdf);
    if (!(max_component(f) > 0.0f && max_component(ls.radiance) > 0.0f)) return;
    ShadowRay ray = std::isinf(ls.distance)
                        ? ShadowRay{offset_ray_origin(sp.position, sp.geometric_normal, ls.wi), ls.wi, ls.distance}
                        : shadow_ray_between(sp.position, sp.geometric_normal, ls.point, ls.normal);
    ++out.rays;
    float w = ls.delta ? 1.0f : power_heuristic(ls.pdf, v.mixture.pdf(bsdf_pdf, ls.wi));
    const bool environment = std::isinf(ls.distance) && !ls.delta;
    const bool lv = s.nonspecular == 0 && (exact || (!all_hv && !environment));
    if constexpr (kClassify) {
      shadows.class_out[shadows.count] = cls->out;
      shadows.classes[shadows.count] = cls->classify(s.nonspecular, false);
    }
    ShadowQueue::Pending pending{&out, s.throughput * f * ls.radiance * (w / ls.pdf), lv};
    if (environment && v.sky.region() != EnvironmentVisibility::kNoRegion && visibility_->learning()) {
      pending.sky_region = v.sky.region();
      pending.sky_value = luminance(ls.radiance) / ls.pdf;
    }
    shadows.push(ray, pending);
  };
  LightSample ls;
  if (u_light.shared ? lights_.sample(sp.position, u_light.point, &ls, &v.sky)
                     : lights_.sample(sp.position, u_light.select, u_light.point, &ls, &v.sky))
    queue_light(ls, false);
  for (size_t k = 0; k < lights_.fixed_light_count(); ++k)
    if (lights_.fixed_light_sample(k, sp.position, &ls)) queue_light(ls, true);
}

// The specular chain a vertex's plan traces (SpecularChainSampler): at every diffuse vertex toward
// every specular object (TraceParams::specular_sampling), else toward the specular objects near the
// first one and the mirror spheres from any (TraceParams::specular_chains). Its light is HV.
template <bool kClassify>
void PathTracer::add_chain_light(Path& path, const Vertex& v, const SpecularChainSampler::Plan& plan,
                                 const TraceParams& params, [[maybe_unused]] ClassState* cls) const {
  PathSample& out = *path.out;
  bool through_glass = false;
  const glm::vec3 light = chains_.light(v.sp, v.bsdf, v.mixture, path.state.throughput, v.index, plan, path.sampler,
                                        params.max_vertices, &out.rays, &through_glass);
  if (max_component(light) > 0.0f) {
    out.hv += light;
    if constexpr (kClassify) {
      const HvClass c = cls->emitter_back_face ? HvClass::EmitterBackFace
                                               : (through_glass ? HvClass::CausticGlass : HvClass::CausticMirror);
      record_hv(*cls->out, light, c);
    }
  }
}

// The vertex's BSDF-side sample: the BSDF's own, or with guiding the one-sample mixture's, weighted
// by f cos / the mixture's pdf whichever strategy drew it. False: no direction.
// *roulette_scale: PathState::roulette_scale, updated for the strategy that drew the sample.
bool PathTracer::sample_bsdf_side(const Vertex& v, const PathSampler::BsdfNumbers& u, PathSampler& sampler,
                                  BsdfSample* bs, float* roulette_scale) const {
  const Bsdf& bsdf = v.bsdf;
  const GuidingMixture& mixture = v.mixture;
  if (!mixture.guided) return bsdf.sample(u.lobe, u.direction, bs);
  // One-sample MIS: either strategy's direction is weighted by f cos / the mixture's pdf.
  const PathSampler::GuidingNumbers g = sampler.guiding_numbers(v.index);
  const float alpha = mixture.alpha;
  if (g.choice < alpha) {
    float guide_pdf, bsdf_pdf;
    bs->wi = mixture.guide.sample(g.direction, &guide_pdf);
    const glm::vec3 f = bsdf.eval(bs->wi, &bsdf_pdf);
    if (!(max_component(f) > 0.0f)) return false;
    bs->pdf = alpha * guide_pdf + (1.0f - alpha) * bsdf_pdf;
    bs->weight = f / bs->pdf;
    *roulette_scale *= unguided_weight_ratio(bs->pdf, bsdf_pdf);
    bs->delta = bs->transmitted = false;
    return true;
  }
  if (!bsdf.sample(u.lobe, u.direction, bs)) return false;
  if (bs->delta) {
    bs->weight /= 1.0f - alpha;  // a delta lobe's share of the mixture
    *roulette_scale *= 1.0f - alpha;
  } else {
    const float pdf = mixture.pdf(bs->pdf, bs->wi);
    bs->weight *= bs->pdf / pdf;
    *roulette_scale *= unguided_weight_ratio(pdf, bs->pdf);
    bs->pdf = pdf;
  }
  return true;
}

// Continues the path by sampling the vertex's BSDF side into path.ray, with Russian roulette.
// False: the path ends here.
template <bool kClassify>
bool PathTracer::continue_path(Path& path, const Vertex& v, const SpecularChainSampler::Plan& plan,
                               const TraceParams& params, const PathSampler::VertexNumbers* numbers,
                               [[maybe_unused]] ClassState* cls) const {
  PathState& s = path.state;
  PathSampler& sampler = path.sampler;
  const SurfacePoint& sp = v.sp;
  const Bsdf& bsdf = v.bsdf;
  const bool roulette = v.index >= params.rr_start_vertex;
  const PathSampler::BsdfNumbers u =
      numbers ? numbers->bsdf : sampler.bsdf_numbers(v.index, bsdf.has_lobe_choice(), roulette);
  BsdfSample bs;
  if (!sample_bsdf_side(v, u, sampler, &bs, &s.roulette_scale)) return false;
  if constexpr (kClassify) {
    if (bs.delta) {
      const bool glass = v.params.transmission > 0.0f && v.params.metallic < 1.0f;
      (glass ? cls->glass_since_d : cls->mirror_since_d) = true;
      if (glass && !sp.front_face && !bs.transmitted) cls->glass_internal = true;
      if (s.nonspecular == 0) cls->specular_before_d = true;
    } else {
      if (s.nonspecular > 0 && (cls->glass_since_d || cls->mirror_since_d)) cls->specular_between_d = true;
      cls->glass_since_d = cls->mirror_since_d = false;
    }
  }
  s.throughput *= bs.weight;
  // Radiance is compressed by eta^2 inside a denser medium (Bsdf's transmitted weight): roulette
  // judges the throughput without that factor (pbrt-v4's etaScale), or it would end about 1 - 1/eta^2
  // of the paths entering glass and give the survivors eta^2 times their weight.
  if (bs.transmitted) s.roulette_scale *= bsdf.eta() * bsdf.eta();
  if (!bs.delta)
    s.chain_mis = plan.traces() ? power_heuristic(bs.pdf, chains_.pdf(sp.position, bs.wi, plan)) : 1.0f;
  else if (!material_is_perfect_specular(*sp.material))
    s.chain_mis = 1.0f;  // a delta lobe of a surface the specular chains stop at
  if (!bs.delta) {
    ++s.nonspecular;
    s.cone_spread = std::max(s.cone_spread, footprint_spread(bs.pdf));
  }
  // Low-discrepancy numbers up to the first non-delta bounce only: deeper vertices gain nothing
  // measurable from them and would pay the scrambling (docs/sampling.md).
  if (s.nonspecular > 0) sampler.leave_qmc();
  s.prev_delta = bs.delta;
  s.prev_pdf = bs.pdf;
  if (roulette) {
    float q = std::min(1.0f, max_component(s.throughput) * s.roulette_scale);
    if (!(u.roulette < q)) return false;
    s.throughput /= q;
  }
  s.prev_position = sp.position;
  if (!bs.delta) s.prev_sky = v.sky;
  path.ray.origin = offset_ray_origin(sp.position, sp.geometric_normal, bs.wi);
  path.ray.direction = bs.wi;
  return true;
}

SurfaceMaterial PathTracer::surface_material(const Ray& camera_ray) const {
  SurfaceMaterial out;
  const Hit hit = geometry_.intersect(camera_ray);
  if (!hit.valid()) return out;
  const Scene& scene = geometry_.scene();
  const SurfacePoint sp = geometry_.surface_point(hit, camera_ray);
  const Material& material = *sp.material;
  const size_t index = static_cast<size_t>(sp.material - scene.materials.data());
  const BsdfParams p = eval_material(scene, material, sp.uv0, sp.uv1, sp.color);
  out.hit = true;
  out.material = material.name.empty() ? "material " + std::to_string(index) : material.name;
  out.base_color = p.base_color;
  out.metallic = p.metallic;
  out.roughness = p.roughness;
  out.transmission = p.transmission;
  out.ior = p.ior;
  out.clearcoat = p.clearcoat;
  out.clearcoat_roughness = p.clearcoat_roughness;
  out.sheen_color = p.sheen_color;
  out.sheen_roughness = p.sheen_roughness;
  if (emission_visible(material, sp)) out.emission = eval_emission(scene, material, sp.uv0, sp.uv1);
  BsdfMaterial scratch;
  const Bsdf bsdf(materials_.at(sp, &scratch), sp.shading_normal, sp.geometric_normal, -camera_ray.direction,
                  sp.front_face, sp.clearcoat_normal);
  if (!bsdf.is_black()) out.lobes = bsdf.lobes();
  return out;
}

bool PathTracer::first_hit_is_emissive(const Ray& camera_ray) const {
  const Hit hit = geometry_.intersect(camera_ray);
  if (!hit.valid()) return false;
  const SurfacePoint sp = geometry_.surface_point(hit, camera_ray);
  return emission_visible(*sp.material, sp);
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
      const bool flip = material.double_sided && glm::dot(n, wo) < 0.0f;
      if (flip) n = -n;
      result.range_color = range_shading(p.base_color * tint, n, wo);
      result.normal = flip ? -sp.shading_normal : sp.shading_normal;
      result.roughness = p.roughness;
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

}  // namespace pxf
