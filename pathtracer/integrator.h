// The unidirectional path tracer (docs/method.md section 1.1): NEE at every non-specular vertex combined with BSDF
// sampling by the power heuristic, Russian roulette, and the LV/HV split of every contribution.
#pragma once
#include <cstdint>
#include <vector>
#include <glm/glm.hpp>
#include "pathtracer/bsdf.h"
#include "pathtracer/caustics/specular_chain_sampler.h"
#include "pathtracer/embree_scene.h"
#include "pathtracer/lights.h"
#include "pathtracer/guiding_mixture.h"
#include "pathtracer/pathtracer.h"
#include "pathtracer/sampler.h"
#include "pathtracer/shading.h"
#include "scene/camera.h"

namespace pxf {

class GuidingField;

// One path's contributions. LV = E S* L and E S* D L (both MIS strategies at that D vertex) but the
// environment's E S* D L; HV = everything else. With all_hv, LV holds only what no random choice
// made noisy: E S* L (what the camera sees directly or through perfectly specular chains) and the
// fixed lights' E S* D L (LightSampler::kMaxFixedLights); everything else goes to HV.
struct PathSample {
  glm::vec3 lv{0.0f};
  glm::vec3 hv{0.0f};
  // The directional albedo of the non-delta lobes of the path's first vertex that has one (through
  // perfectly specular chains, not tinted by them): Bsdf::nondelta_albedo. 0 when the path escapes
  // or ends before such a vertex. A pixel's mean albedo is then its coverage times its surfaces'
  // albedo, and HV, which only paths through such a vertex carry, divided by it is the light
  // arriving there, even where a thin surface covers part of the pixel (gl/demodulation.h).
  glm::vec3 albedo{0.0f};
  uint32_t rays = 0;
  bool finite() const;
};

// Firefly attribution (docs/sampling.md#fireflies): the kind of path an HV contribution came from,
// in order of precedence (the first that fits). "S" is a delta interaction (mirror or smooth glass),
// "D" any other scattering vertex. Only trace_pixels_classified computes it; renders never do.
enum class HvClass : uint8_t {
  None,                  // the sample has no HV light
  EmitterBackFace,       // the path scattered off the back (non-emitting) face of an emitter
  GlassInternal,         // a delta reflection inside glass (Fresnel or total internal reflection)
  CausticGlass,          // E ... D S+ L with glass in the chain: emission found by BSDF sampling, NEE blocked
  CausticMirror,         // E ... D S+ L through mirrors only
  SpecularBetweenDiffuse,  // E ... D S+ D ... L: a specular chain between two diffuse vertices
  SeenThroughSpecular,   // E S+ D ... L: the camera sees the diffuse surface through glass or a mirror
  Diffuse,               // E D D+ L: plain diffuse interreflection
  Count
};
const char* hv_class_name(HvClass c);
// One sample's HV classification: its largest HV contribution's class and luminance.
struct HvSampleClass {
  HvClass dominant = HvClass::None;
  float dominant_luminance = 0.0f;
};

// The pixels [x0, x1) x [y0, y1) of an image.
struct PixelRect {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  int width() const { return x1 - x0; }
  int count() const { return (x1 - x0) * (y1 - y0); }
};

// One path to trace: pixel (x, y) at sample index `index` (the frame of a uniform frame; with
// adaptive sampling the pixel's own count of traced paths, docs/sampling.md).
struct PixelSampleJob {
  int x = 0, y = 0;
  uint32_t index = 0;
};

class PathTracer {
 public:
  explicit PathTracer(const Scene& scene);

  // One path for each pixel of `rect` in frame `frame`; out[i] is the i-th pixel in row-major
  // order (rect.count() entries). The paths of a batch advance together, one vertex at a time, so
  // each vertex's rays reach Embree as one stream. A path's random stream depends only on
  // (params.seed, pixel, frame), and a stream answers each ray as a single-ray query would, so
  // neither the rect nor the thread changes a pixel's value.
  void trace_pixels(const Camera& camera, int width, int height, const PixelRect& rect, uint32_t frame,
                    const TraceParams& params, PathSample* out) const;
  // One path per job, out[i] for jobs[i]: the pixels of a frame that traces only some of them (a
  // compacted list, so that the batches stay full). The same samples as trace_pixels gives each
  // pixel at that index, bit for bit.
  void trace_jobs(const Camera& camera, int width, int height, const PixelSampleJob* jobs, int count,
                  const TraceParams& params, PathSample* out) const;
  // The path of pixel (x, y): trace_pixels on that pixel alone.
  PathSample trace_pixel(const Camera& camera, int width, int height, int x, int y, uint32_t frame,
                         const TraceParams& params) const;

  // trace_pixels (the same samples, bit for bit) that also classifies every HV contribution; for the
  // firefly attribution in tests, never used by renders: trace_pixels compiles without it.
  void trace_pixels_classified(const Camera& camera, int width, int height, const PixelRect& rect, uint32_t frame,
                               const TraceParams& params, PathSample* out, HvSampleClass* classes) const;

  SpecularChainHit trace_specular_chain(const Ray& camera_ray) const;
  // The material the ray meets first (ProgressiveRenderer::surface_material).
  SurfaceMaterial surface_material(const Ray& camera_ray) const;
  // The ray's first surface emits toward it (the emission the path tracer adds at vertex 1).
  bool first_hit_is_emissive(const Ray& camera_ray) const;

  // Path guiding (TraceParams::guiding, docs/guiding.md): traces whose params.guiding is not Off
  // sample from `field` once it is trained(), and trace_guiding_photons records into it; nullptr
  // (the default, and Auto's until it starts) traces without guiding whatever params.guiding
  // says. The field must not change (apply_records, end_iteration) while a trace runs.
  void set_guiding(GuidingField* field) { guiding_ = field; }
  // Light through openings (TraceParams::environment_visibility, environment_visibility.h): NEE
  // toward the environment samples what each vertex's region learned of the visible sky, and every
  // unblocked environment sample is recorded there. nullptr (the default): the environment is
  // sampled by its radiance alone. The field must not change (end_frame) while a trace runs.
  void set_environment_visibility(EnvironmentVisibility* field) { visibility_ = field; }
  // Ray recording (EmbreeScene::set_ray_recorder): every ray the traces hand to Embree is logged there.
  void set_ray_recorder(RayRecorder* recorder) { geometry_.set_ray_recorder(recorder); }

  // Path guiding's training light (docs/guiding.md): `count` photons of frame `frame`, traced from
  // the lights; at every non-delta surface a photon reaches after its first bounce (light NEE does
  // not find), the field records the flux that arrived and the direction it came from. A photon's
  // numbers depend on (params.seed, frame, its index) only and the field orders its records, so
  // the field does not depend on the thread count. Call it between frames, with a field set.
  void trace_guiding_photons(uint32_t frame, int count, const TraceParams& params) const;

  bool dark() const { return lights_.empty(); }
  bool has_perfect_specular() const { return chains_.has_perfect_specular(); }
  const EmbreeScene& geometry() const { return geometry_; }
  const LightSampler& lights() const { return lights_; }

 private:
  struct Path;
  struct ShadowQueue;
  struct ClassState;
  struct Vertex;
  template <bool kClassify>
  void trace_batch(const Camera& camera, int width, int height, const PixelSampleJob* jobs, int count,
                   const TraceParams& params, PathSample* out, HvSampleClass* classes) const;
  void trace_guiding_photon(uint32_t frame, uint32_t index, const TraceParams& params) const;
  // One path vertex (shade_vertex) and its parts: the guided mixture it samples from, next event
  // estimation, the specular chain's light, and the BSDF sample that continues the path.
  template <bool kClassify>
  bool shade_vertex(Path& path, const Hit& hit, int vertex, const TraceParams& params, ShadowQueue& shadows,
                    const PathSampler::VertexNumbers* numbers, ClassState* cls) const;
  GuidingMixture guiding_mixture(const SurfacePoint& sp, const Bsdf& bsdf, glm::vec3 wo, const TraceParams& params) const;
  template <bool kClassify>
  void sample_direct_light(Path& path, const Vertex& v, const PathSampler::LightNumbers& u_light, bool all_hv,
                           ShadowQueue& shadows, ClassState* cls) const;
  template <bool kClassify>
  void add_chain_light(Path& path, const Vertex& v, const SpecularChainSampler::Plan& plan, const TraceParams& params,
                       ClassState* cls) const;
  template <bool kClassify>
  bool continue_path(Path& path, const Vertex& v, const SpecularChainSampler::Plan& plan, const TraceParams& params,
                     const PathSampler::VertexNumbers* numbers, ClassState* cls) const;
  bool sample_bsdf_side(const Vertex& v, const PathSampler::BsdfNumbers& u, PathSampler& sampler, BsdfSample* bs,
                        float* roulette_scale) const;

  EmbreeScene geometry_;
  LightSampler lights_;
  BsdfMaterials materials_;
  SpecularChainSampler chains_;  // light through specular chains (caustics)
  GuidingField* guiding_ = nullptr;
  EnvironmentVisibility* visibility_ = nullptr;
};

}  // namespace pxf
