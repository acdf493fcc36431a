// Public API of the path tracer (SPEC 3.1): a progressive state with make/step/get functions in the
// style of yocto_trace. No GL here; the GL passes read these buffers and upload them.
#pragma once
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>
#include <glm/glm.hpp>
#include "image/image.h"
#include "pathtracer/scene.h"

namespace pxf {

struct TraceParams {
  int max_vertices = 6;     // path length in vertices, camera and light vertex included
  int rr_start_vertex = 3;  // Russian roulette from this vertex on
  bool all_hv = false;      // every contribution goes to HV (environment-lit scenes)
  uint64_t seed = 1;
  int threads = 0;          // 0 = all cores
};

// Loads a glTF/GLB file or a built-in scene name ("cornell", ...); throws pxf::Error naming the
// file and the problem. `env_path` (optional) replaces the environment with an equirect EXR.
Scene load_scene(const std::string& name_or_path, const std::string& env_path = "", float env_strength = 1.0f);
// The same from a glTF/GLB already in memory (the fuzzer's entry point); `name` prefixes errors and
// relative uris resolve against `base_dir`.
Scene load_scene_from_memory(const std::vector<unsigned char>& bytes, const std::string& name,
                             const std::string& base_dir);
// The built-in scenes: name and one-line description.
struct BuiltinScene { std::string name, description, path; };
std::vector<BuiltinScene> builtin_scenes();

// The range-buffer color of a surface: albedo times a noise-free shading term that separates
// differently oriented surfaces (SPEC 3.2). The raster shader implements the same formula.
inline glm::vec3 range_shading(glm::vec3 albedo, glm::vec3 normal, glm::vec3 to_viewer) {
  float c = glm::dot(normal, to_viewer);
  return albedo * (0.2f + 0.8f * (c > 0.0f ? c : 0.0f));
}

// The range-buffer color where a ray escapes to the environment: its radiance compressed to
// [0, 1) per channel by L / (1 + L), so that bright and dark parts of the environment (a softbox,
// the backdrop) differ in range color and the filter does not mix them. The raster pass
// (shaders/range_background.frag) computes the same for camera rays that miss the scene.
inline glm::vec3 range_environment_color(glm::vec3 radiance) {
  if (!std::isfinite(radiance.x) || !std::isfinite(radiance.y) || !std::isfinite(radiance.z)) return glm::vec3(0.0f);
  glm::vec3 l = glm::max(radiance, glm::vec3(0.0f));
  return l / (1.0f + l);
}

// Result of following a perfectly specular chain from the camera (SPEC 3.2).
struct SpecularChainHit {
  // hit: albedo x chain tint x range_shading at the first non-specular hit; escaped:
  // range_environment_color(chain tint x environment radiance), black without an environment.
  glm::vec3 range_color{0.0f};
  float distance = 0.0f;  // total distance along the chain, scene units (hit only)
  bool hit = false;       // false: the chain escaped (the range pass uses the background distance)
};

// Per-pixel accumulations, row-major, top row first.
struct Accumulation {
  int width = 0, height = 0;
  std::vector<glm::vec3> lv_mean;      // mean RGB radiance of LV paths
  std::vector<glm::vec3> hv_mean;      // mean RGB radiance of HV paths
  std::vector<double> hv_lum_mean;     // Welford state of HV luminance
  std::vector<double> hv_lum_m2;
  std::vector<uint32_t> samples;       // accepted samples per pixel (NaN/Inf samples dropped)
  // Var[L_u] = s^2 / n of the HV luminance mean; negative (-1) when n < 2 (unknown).
  float variance_of_mean(size_t pixel) const;
};

struct TraceStats {
  uint64_t paths = 0;
  uint64_t rays = 0;             // all rays: camera, continuation and shadow rays
  uint64_t nan_samples_dropped = 0;
  double last_frame_ms = 0;
};

class PathTracer;  // Embree scene, light and environment samplers (pathtracer internals)

// The progressive state: one path per pixel per add_frame().
class ProgressiveRenderer {
 public:
  ProgressiveRenderer(const Scene& scene, const TraceParams& params, int width, int height);
  ~ProgressiveRenderer();
  ProgressiveRenderer(const ProgressiveRenderer&) = delete;
  ProgressiveRenderer& operator=(const ProgressiveRenderer&) = delete;

  void reset();                          // clears accumulation (camera, scene or params changed)
  void set_camera(const Camera& camera); // resets
  void set_params(const TraceParams& params);  // resets
  void add_frame();                      // traces one path per pixel, frame index = frames()
  int frames() const;

  const Accumulation& accumulation() const;
  const TraceStats& stats() const;
  const Scene& scene() const;
  const Camera& camera() const;
  const TraceParams& params() const;
  int width() const;
  int height() const;

  Image lv_image() const;          // RGB
  Image hv_image() const;          // RGB
  Image unfiltered_image() const;  // RGB L_lv + L_u: what plain path tracing shows
  Image variance_image() const;    // "Y": Var[L_u], 0 where unknown
  Image samples_image() const;     // "Y": n
  std::vector<float> variance_of_mean() const;  // Var[L_u] per pixel, -1 where n < 2

  // True when a perfectly specular surface is directly visible somewhere (cheap check by the
  // caller's raster flag is preferred; this is what the renderer knows from its materials).
  bool scene_has_perfect_specular() const;
  // Follows the specular chain for the camera rays through (x + jitter) of the given pixels.
  std::vector<SpecularChainHit> trace_specular_chains(const std::vector<uint32_t>& pixels, glm::vec2 jitter) const;

  // The scene has no emitter and no environment: add_frame() only counts the frame.
  bool scene_is_dark() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pxf
