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
#include "core/memory.h"  // available_memory_bytes, which LoadLimits defaults to
#include "image/image.h"
#include "pathtracer/default_light.h"
#include "pathtracer/sampler.h"
#include "pathtracer/scene.h"
#include "shaders/range_formulas.h"

namespace pxf {

struct TraceParams {
  int max_vertices = 6;     // path length in vertices, camera and light vertex included
  int rr_start_vertex = 3;  // Russian roulette from this vertex on
  bool all_hv = false;      // every contribution but E S* L goes to HV (environment-lit scenes)
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
  // Near specular sampling, the default: the same chains at the first diffuse vertex only, toward the
  // specular objects whose bounding sphere subtends at least kNearSpecularSolidAngle from it. That
  // is where a glass object focuses the light onto the floor it stands on, a caustic that BSDF
  // sampling finds in a few % of its samples; there a chain costs little (few first vertices are
  // that near) and about halves the variance there (docs/sampling.md#near-specular-sampling). Ignored with
  // specular_sampling, which does this and more.
  bool near_specular_sampling = true;
  // Path guiding (docs/guiding.md): the renderer learns an SD-tree of the indirect light from
  // photons it traces from the lights after each frame, and once trained each path's first
  // non-delta vertex samples its direction from it with the probability its region learned (times
  // the BSDF's diffuse share), from the BSDF otherwise, weighted by the mixture pdf (one-sample MIS;
  // NEE and specular sampling MIS against that mixture). Off by default; off traces the samples
  // of before, bit for bit.
  bool guiding = false;
};

// A sphere subtends solid angle 2 pi (1 - cos a) from a point at distance d from its center, with
// sin a = r / d. Near: at least pi sr (a >= 60 degrees), i.e. d^2 <= r^2 / sin^2 a = r^2 / (1 - cos^2 a).
constexpr float kNearSpecularSolidAngle = 3.14159265358979323846f;
constexpr float kNearSpecularCosHalfAngle = 1.0f - kNearSpecularSolidAngle / (2.0f * 3.14159265358979323846f);
constexpr float kNearSpecularDistance2PerRadius2 = 1.0f / (1.0f - kNearSpecularCosHalfAngle * kNearSpecularCosHalfAngle);
// ... and only toward a mesh whose area is at least this share of its bounding sphere's (on average
// it then covers at least this share of the cone the chain samples).
constexpr double kNearSpecularMinFill = 0.5;

// The specular sampling a TraceParams asks for, as the state files number it: near sampling means
// nothing while full specular sampling is on, so two params that differ only there trace the same
// samples.
enum class SpecularSamplingMode : uint32_t { None = 0, All = 1, Near = 2 };
inline SpecularSamplingMode specular_sampling_mode(const TraceParams& p) {
  return p.specular_sampling         ? SpecularSamplingMode::All
         : p.near_specular_sampling ? SpecularSamplingMode::Near
                                    : SpecularSamplingMode::None;
}

// The replicates an accumulation keeps sums for: only the Sobol sampler has any (independent
// samples are their own replicates). The renderer and the state files both go by this.
inline int accumulated_replicates(SamplerType sampler, int replicates) {
  return sampler == SamplerType::Sobol ? std::max(replicates, 1) : 1;
}

// What a scene may demand. The loader counts the instanced triangles (every mesh once per node
// that references it) and reads the used images' headers before it reads any geometry or decodes
// any texture; over a cap, or with an estimate over the available memory, it refuses.
struct LoadLimits {
  static constexpr int kDefaultMaxTextureSize = 16384;
  static constexpr uint64_t kDefaultMaxTriangles = 100'000'000;
  int max_texture_size = kDefaultMaxTextureSize;  // texels, per side
  uint64_t max_triangles = kDefaultMaxTriangles;  // instanced triangles in the whole scene
  uint64_t available_memory = 0;                  // bytes; 0 = what the system reports now
};


// The loader's memory estimate for a scene, in bytes: what the loaded scene, the BVH, the raster
// pass's copies and the decoding need at the peak (docs/scenes.md, "Resource limits").
struct LoadEstimate {
  uint64_t vertices = 0, triangles = 0;  // instanced
  uint64_t meshes = 0;                   // instanced primitives: each a Mesh, a BVH geometry, a draw
  uint64_t lights = 0;                   // instanced punctual lights
  uint64_t texture_bytes = 0;            // stored texels of the used textures
  uint64_t largest_decode_bytes = 0;     // the largest image's decoding buffers
  uint64_t environment_texels = 0;       // the environment map's (--env or the scene's own)
  uint64_t bytes() const;
};

// The glTF/GLB file and the files its uris name (buffers, images) are read up to 4 GiB - 1: tinygltf
// takes a file's length as an unsigned int, and a GLB stores its lengths in 32 bits.
constexpr uint64_t kMaxGltfFileBytes = 0xffffffff;

// Loads a glTF/GLB file or a built-in scene name ("cornell", ...); throws pxf::Error naming the
// file and the problem. `env_path` (optional) replaces the environment with an equirectangular
// EXR or Radiance .hdr (checked before the scene loads). A scene without any light gets the
// built-in `default_light` environment (Scene::notes says so); with None a warning says it is black.
// Before anything large is allocated, the loader checks `limits` (see LoadLimits) and refuses
// with a one-line error naming the file and the limit.
Scene load_scene(const std::string& name_or_path, const std::string& env_path = "", float env_strength = 1.0f,
                 DefaultLight default_light = DefaultLight::None, const LoadLimits& limits = {});
// The same from a glTF/GLB already in memory (the fuzzer's entry point); `name` prefixes errors and
// relative uris resolve against `base_dir`.
Scene load_scene_from_memory(const std::vector<unsigned char>& bytes, const std::string& name,
                             const std::string& base_dir, const LoadLimits& limits = {});
// The built-in scenes: name and one-line description.
struct BuiltinScene { std::string name, description, path; };
std::vector<BuiltinScene> builtin_scenes();

// The range-buffer colors of a surface and of the environment (docs/method.md section 1.2), which
// the raster pass's shaders compute from the same source (shaders/range_formulas.h).
using shared::range_environment_color;
using shared::range_shading;

// Result of following a perfectly specular chain from the camera (docs/method.md section 1.2).
struct SpecularChainHit {
  // hit: albedo x chain tint x range_shading at the first non-specular hit; escaped:
  // range_environment_color(chain tint x environment radiance), black without an environment.
  glm::vec3 range_color{0.0f};
  float distance = 0.0f;  // total distance along the chain, scene units (hit only)
  bool hit = false;       // false: the chain escaped (the range pass uses the background distance)
};

// The material under a pixel as the path tracer shades the camera ray's first surface (the
// explorer's inspector, issue 35): its evaluated parameters there (textures and vertex colour
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

// Per-pixel accumulations, row-major, top row first.
struct Accumulation {
  int width = 0, height = 0;
  std::vector<glm::vec3> lv_mean;      // mean RGB radiance of LV paths
  std::vector<glm::vec3> hv_mean;      // mean RGB radiance of HV paths
  std::vector<glm::vec3> albedo_mean;  // mean PathSample::albedo (first non-specular base color)
  std::vector<double> hv_lum_mean;     // Welford state of HV luminance
  std::vector<double> hv_lum_m2;
  // Welford state of LV luminance: LV is never filtered, so its noise is part of what the viewer
  // sees; adaptive sampling judges the final pixel L_lv + L_u by it (app/adaptive.h).
  std::vector<double> lv_lum_mean;
  std::vector<double> lv_lum_m2;
  std::vector<uint32_t> samples;       // accepted samples per pixel (NaN/Inf samples dropped)
  // Interleaved replicates (TraceParams::replicates, 1 = none): HV luminance sum and sample count
  // of replicate r of pixel p at [p * replicates + r].
  int replicates = 1;
  std::vector<double> replicate_lum_sum;
  std::vector<uint32_t> replicate_samples;

  // Var[L_u] of the HV luminance mean; negative (-1) when n < 2 (unknown). Without replicates it is
  // s^2 / n. With replicates (randomized QMC, where s^2 / n overestimates), it is s^2 / n times the
  // QMC gain: the sum over the 3x3 neighbourhood of the replicate estimates divided by the sum of
  // the s^2 / n estimates. Each replicate estimate alone has only K - 1 degrees of freedom; pooling
  // the gain, which varies slowly across the image, keeps the n - 1 of s^2 / n.
  float variance_of_mean(size_t pixel) const;
  std::vector<float> variance_of_mean_image() const;  // variance_of_mean of every pixel, in O(pixels)
  void variance_of_mean_image(float* out, size_t stride) const;  // the same into out[pixel * stride]
  // 4 floats per pixel: rgb hv_mean, a variance_of_mean (-1 where n < 2). The preview uploads this
  // buffer as its HV texture as it is.
  void hv_and_variance_of_mean(float* rgba) const;
  float per_sample_variance_of_mean(size_t pixel) const;  // s^2 / n, -1 when n < 2
  // Var[L_lv] of the LV luminance mean, s^2 / n (no replicate gain); -1 when n < 2.
  float lv_variance_of_mean(size_t pixel) const;
  // K'/(K'-1) sum_r (n_r / n)^2 (m_r - m)^2 over the K' replicates with samples; -1 when K' < 2.
  float replicate_variance_of_mean(size_t pixel) const;
};

struct TraceStats {
  uint64_t paths = 0;
  uint64_t rays = 0;             // all rays: camera, continuation and shadow rays
  uint64_t nan_samples_dropped = 0;
  double last_frame_ms = 0;
};

class PathTracer;  // Embree scene, light and environment samplers (pathtracer internals)

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
  // (guiding_field()); with TraceParams::guiding an empty one starts a new field (the render then
  // does not continue exactly), without guiding it is ignored. Throws pxf::Error on a field that
  // does not deserialize.
  void restore(const Accumulation& acc, uint32_t first, int frames, const std::vector<uint32_t>& traced = {},
               const std::vector<uint8_t>& guiding_field = {});
  // The guiding field learned so far, serialized (empty without TraceParams::guiding), and its
  // memory (GuidingField::memory_bytes(), 0 without guiding).
  std::vector<uint8_t> guiding_field() const;
  size_t guiding_memory_bytes() const;

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

 private:
  struct Impl;
  bool add_frame_of(const uint8_t* active);  // nullptr: every pixel
  std::unique_ptr<Impl> impl_;
};

}  // namespace pxf
