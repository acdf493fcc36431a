// Public API of the path tracer (docs/method.md section 1.1): a progressive state with make/step/get functions in the
// style of yocto_trace. No GL here; the GL passes read these buffers and upload them.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>
#include <glm/glm.hpp>
#include "image/image.h"
#include "pathtracer/accumulation.h"
#include "pathtracer/sampler.h"
#include "scene/range.h"
#include "scene/scene.h"

namespace pxf {

// Path guiding's mode (TraceParams::guiding). Auto: on from the frame at which the environment
// visibility field (environment_visibility.h) finds that the scene sees at most half of its sky,
// a room lit through its windows, where light is hard to find; off for good everywhere else (an
// object under a sky, a scene without an environment, --env-visibility off), where it costs more
// than it gains (docs/guiding.md). Where it stays off, auto traces the samples of off bit for bit.
enum class GuidingMode { Off, On, Auto };
// Names of GuidingMode (index = value): "off", "on", "auto".
inline const std::vector<std::string>& guiding_mode_names() {
  static const std::vector<std::string> names = {"off", "on", "auto"};
  return names;
}

struct TraceParams {
  int max_vertices = 6;     // path length in vertices, camera and light vertex included
  int rr_start_vertex = 3;  // Russian roulette from this vertex on
  bool all_hv = false;      // the emitters' first-surface light to HV too, not only the environment's (PathSample)
  uint64_t seed = 1;
  int threads = 0;          // 0 = all cores
  SamplerType sampler = SamplerType::Sobol;  // see pathtracer/sampler.h for the dimension table
  // Independently scrambled interleaved Sobol replicates (frame k is in replicate k mod K): their
  // means give Var[L_u] of the pixel mean under QMC. 1 = one sequence and the estimate s^2 / n.
  // Default 1: K > 1 makes the estimate exact on average but costs unfiltered error (each
  // replicate is a shorter sequence), and s^2 / n overestimates only mildly (docs/sampling.md).
  int replicates = 1;
  // Specular sampling: at each diffuse vertex, a direction in the cone of one perfectly specular
  // object's bounding sphere, followed through its specular chain to the light it reaches (the
  // caustics that NEE cannot see), combined with BSDF sampling by the power heuristic
  // (docs/sampling.md#fireflies). Off by default.
  bool specular_sampling = false;
  // Specular chains, the default: the chains of specular_sampling only where they pay. From the
  // first diffuse vertex toward the specular objects whose bounding sphere subtends at least
  // kNearSpecularSolidAngle from it: that is where a glass object focuses the light onto the floor
  // it stands on, a caustic that BSDF sampling finds in a few % of its samples, and there a chain
  // costs little (few first vertices are that near) and about halves the variance. From every
  // other diffuse vertex (and the first where nothing is near), toward the mirror spheres in 1 of
  // 20: their solved chains find a mirror's caustic on every wall. See
  // pathtracer/caustics/specular_chain_sampler.h and docs/sampling.md#specular-chains.
  // Ignored with specular_sampling, which does this and more.
  bool specular_chains = true;
  // Path guiding (docs/guiding.md): the renderer learns an SD-tree of the indirect light from
  // photons it traces from the lights after each frame, and once trained every non-delta vertex of
  // a path samples its direction from it with the probability its region learned (times
  // the BSDF's diffuse share), from the BSDF otherwise, weighted by the mixture pdf (one-sample MIS;
  // NEE and specular sampling MIS against that mixture). Off traces the samples of before, bit for
  // bit. Auto (the default) starts it where it pays, a scene lit through openings (GuidingMode).
  GuidingMode guiding = GuidingMode::Auto;
  // Light through openings (docs/sampling.md#light-through-openings): in a scene with an
  // environment, next event estimation learns per region which parts of the sky its shadow rays
  // find unblocked, and draws half of its environment directions from that (MIS-combined with
  // the environment's own distribution: unbiased). On by default; without an environment it does
  // nothing.
  bool environment_visibility = true;
  // The blend's split decision (BlendParams::split, docs/method.md section 3.8): the accumulation
  // also keeps the even half of each pixel's samples, and the blend weighs each half by the weight
  // the other half's variance decides, so that the decision does not correlate with the samples it
  // weighs (one decision darkens: 4.3 % on `window` at 32 spp). Off by default: it keeps half of
  // each outlier (display error 1.05-1.2x at equal time), and the half's arrays cost about 6 % of
  // path tracing, so a render pays for them only where the blend reads them.
  bool split_halves = false;
};

// The specular sampling a TraceParams asks for, as the state files number it: specular_chains
// means nothing while full specular sampling is on, so two params that differ only there trace the
// same samples.
enum class SpecularSamplingMode : uint32_t { None = 0, All = 1, Chains = 2 };
inline SpecularSamplingMode specular_sampling_mode(const TraceParams& p) {
  return p.specular_sampling ? SpecularSamplingMode::All
         : p.specular_chains ? SpecularSamplingMode::Chains
                             : SpecularSamplingMode::None;
}

// The replicates an accumulation keeps sums for: only the Sobol sampler has any (independent
// samples are their own replicates). The renderer and the state files both go by this.
inline int accumulated_replicates(SamplerType sampler, int replicates) {
  return sampler == SamplerType::Sobol ? std::max(replicates, 1) : 1;
}

// The material under a pixel as the path tracer shades the camera ray's first surface (the
// explorer's inspector): its evaluated parameters there (textures and vertex colour
// applied) and the lobes its BSDF samples from, each with the probability sample() picks it.
struct SurfaceLobe {
  std::string name;  // diffuse, glossy, sheen, clearcoat, glass
  float probability = 0.0f;
  bool delta = false;  // perfectly specular: a mirror direction, which the range buffer follows
};
struct SurfaceMaterial {
  bool hit = false;  // false: the ray left the scene (the environment)
  std::string material;  // the glTF material's name, else "material N"
  glm::vec3 base_color{0.0f};
  float metallic = 0.0f, roughness = 0.0f, transmission = 0.0f, ior = 1.5f;
  float clearcoat = 0.0f, clearcoat_roughness = 0.0f;
  glm::vec3 sheen_color{0.0f};
  float sheen_roughness = 0.0f;
  glm::vec3 emission{0.0f};  // toward the camera (0 from the back of a one-sided emitter)
  std::vector<SurfaceLobe> lobes;
};

struct TraceStats {
  uint64_t paths = 0;
  uint64_t rays = 0;             // all rays: camera, continuation and shadow rays
  uint64_t nan_samples_dropped = 0;
  double last_frame_ms = 0;
};

// The environment's share of the scene's light, as next event estimation weighs its light types by
// their estimated power (LightSampler); 0 without an environment.
float environment_light_share(const Scene& scene);

class PathTracer;  // Embree scene, light and environment samplers (pathtracer internals)
class RayRecorder;  // pathtracer/ray_recorder.h (internals)

// The most paths one pixel traces in one frame (adaptive sampling's counts).
constexpr uint32_t kMaxPathsPerFrame = 32;

// The progressive state: one path per pixel (or a count per pixel) per add_frame().
class ProgressiveRenderer {
 public:
  // The renderer keeps a reference to `scene`, not a copy: the scene must outlive the renderer and
  // stay unchanged while it exists. A temporary scene does not compile.
  ProgressiveRenderer(const Scene& scene, const TraceParams& params, int width, int height);
  ProgressiveRenderer(Scene&& scene, const TraceParams& params, int width, int height) = delete;
  ~ProgressiveRenderer();
  ProgressiveRenderer(const ProgressiveRenderer&) = delete;
  ProgressiveRenderer& operator=(const ProgressiveRenderer&) = delete;

  void reset();                          // clears accumulation (camera, scene or params changed)
  void set_camera(const Camera& camera); // resets
  void set_params(const TraceParams& params);  // resets
  // Traces one path per pixel, each at its own sample index first_frame() * the sample stride +
  // pixel_frames()[p] (first_frame() + frames() while every frame traced every pixel). Returns false when
  // cancel_frame() stopped it: the frame is then incomplete and the accumulation is reset.
  bool add_frame();
  // The same with `counts[p]` paths for pixel p (width x height entries, row-major, 0 = none;
  // adaptive sampling, docs/sampling.md): the paths are compacted into full batches, and pixel p
  // traces the next counts[p] samples of its own sequence, so the result does not depend on the
  // thread count nor on how the paths were spread over frames. Throws pxf::Error when the counts'
  // size is not the image's or a count is over kMaxPathsPerFrame.
  bool add_frame(const std::vector<uint8_t>& counts);
  // Thread-safe: a running add_frame() (on another thread) stops after the tiles in flight. For a
  // caller about to reset anyway (the explorer's camera moves), so that it need not wait a frame.
  void cancel_frame();
  int frames() const;                    // frames traced (or restored) since the last reset
  // Paths traced into each pixel since the last reset (restored frames included), dropped
  // non-finite ones too: the pixel's next sample index is first_frame() * stride + this. Accumulation::samples
  // counts the accepted ones only.
  const std::vector<uint32_t>& pixel_frames() const;
  // Where the frame sequence starts (a shard of frames A:B starts at A); resets.
  void set_first_frame(uint32_t first);
  uint32_t first_frame() const;
  // Frame f's first sample index is f * stride (default 1; from the next frame on, which matters
  // only where first_frame() > 0). Adaptive sampling, which traces
  // up to kMaxPathsPerFrame paths per pixel a frame, sets kMaxPathsPerFrame, so that shards of
  // disjoint frames keep disjoint sample indices however their allocations spread the paths.
  void set_sample_stride(uint32_t stride);
  // Continues from a saved accumulation holding the frames [first, first + frames) (checkpoint
  // resume, merged shards). `traced`: each pixel's traced paths (pixel_frames(); an adaptive
  // render's), empty = `frames` for every pixel. Throws pxf::Error when a size differs from the
  // renderer's.
  // `guiding_field`: GuidingField::serialize() of the field the saved render had learned
  // (guiding_field()); under GuidingMode::On an empty one starts a new field (the render then
  // does not continue exactly), under Auto an empty one means none has started (one starts as in
  // a render from the start, at the visibility field's verdict), under Off it is ignored. Throws
  // pxf::Error on a field that does not deserialize.
  // `environment_visibility`: EnvironmentVisibility's serialized state (environment_visibility());
  // empty starts a new one, which continues unbiased but not bit for bit.
  void restore(const Accumulation& acc, uint32_t first, int frames, const std::vector<uint32_t>& traced = {},
               const std::vector<uint8_t>& guiding_field = {}, const std::vector<uint8_t>& environment_visibility = {});
  // The guiding field learned so far, serialized (empty while guiding is not active), and its
  // memory (GuidingField::memory_bytes(), 0 while guiding is not active).
  std::vector<uint8_t> guiding_field() const;
  size_t guiding_memory_bytes() const;
  // Whether guiding runs now: always under GuidingMode::On, once started under Auto.
  bool guiding_active() const;
  // What light through openings learned so far, serialized (empty where it is off or the scene has
  // no environment), and its regions with a learned distribution.
  std::vector<uint8_t> environment_visibility() const;
  size_t environment_visibility_regions() const;

  const Accumulation& accumulation() const;
  const TraceStats& stats() const;
  const Scene& scene() const;
  const Camera& camera() const;
  const TraceParams& params() const;
  int width() const;
  int height() const;

  Image lv_image() const;          // RGB
  Image hv_image() const;          // RGB
  Image albedo_image() const;      // RGB: mean first non-specular albedo (PathSample::albedo)
  Image unfiltered_image() const;  // RGB L_lv + L_u: what plain path tracing shows
  Image variance_image() const;    // "Y": Var[L_u], 0 where unknown
  Image samples_image() const;     // "Y": n
  std::vector<float> variance_of_mean() const;  // Var[L_u] per pixel, -1 where n < 2
  // "Y": the fraction of each pixel's camera rays whose first visible surface is emissive, from
  // kEmitterRaysPerSide^2 stratified rays per pixel traced on demand (once per output, not per
  // frame). Lets metrics leave the light sources out.
  Image emitter_coverage_image() const;
  static constexpr int kEmitterRaysPerSide = 2;

  // True when a perfectly specular surface is directly visible somewhere (cheap check by the
  // caller's raster flag is preferred; this is what the renderer knows from its materials).
  bool scene_has_perfect_specular() const;
  // The material the camera ray through the centre of pixel (x, y) meets first.
  SurfaceMaterial surface_material(int x, int y) const;
  // Follows the specular chain for the camera rays through (x + jitter) of the given pixels.
  std::vector<SpecularChainHit> trace_specular_chains(const std::vector<uint32_t>& pixels, glm::vec2 jitter) const;

  // The scene has no emitter and no environment: add_frame() only counts the frame.
  bool scene_is_dark() const;

  // The throughput bench and tests: while `recorder` is set, every ray the frames hand to Embree
  // (paths, shadow rays, specular chains; guiding's photons too) is logged there; nullptr stops.
  // The renderer does not own it. Set it between frames. tracer(): the internals that trace.
  void set_ray_recorder(RayRecorder* recorder);
  const PathTracer& tracer() const;

 private:
  struct Impl;
  bool add_frame_of(const uint8_t* active);  // nullptr: every pixel
  std::unique_ptr<Impl> impl_;
};

}  // namespace pxf
