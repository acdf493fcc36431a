// The unidirectional path tracer of SPEC 3.1: NEE at every non-specular vertex combined with BSDF
// sampling by the power heuristic, Russian roulette, and the LV/HV split of every contribution.
#pragma once
#include <cstdint>
#include <glm/glm.hpp>
#include "pathtracer/camera.h"
#include "pathtracer/embree_scene.h"
#include "pathtracer/lights.h"
#include "pathtracer/pathtracer.h"

namespace pxf {

// One path's contributions. LV = E S* L and E S* D L (both MIS strategies at that D vertex);
// HV = everything else. With all_hv, lv stays 0.
struct PathSample {
  glm::vec3 lv{0.0f};
  glm::vec3 hv{0.0f};
  uint32_t rays = 0;
  bool finite() const;
};

class PathTracer {
 public:
  explicit PathTracer(const Scene& scene);

  // The path of pixel (x, y) in frame `frame`; its random stream depends only on
  // (params.seed, pixel, frame).
  PathSample trace_pixel(const Camera& camera, int width, int height, int x, int y, uint32_t frame,
                         const TraceParams& params) const;
  // The path along a given camera ray (rng stream as for pixel `pixel_index`).
  PathSample trace_ray(const Ray& camera_ray, uint64_t pixel_index, uint32_t frame, const TraceParams& params) const;

  SpecularChainHit trace_specular_chain(const Ray& camera_ray) const;

  bool dark() const { return lights_.empty(); }
  bool has_perfect_specular() const { return has_perfect_specular_; }
  const EmbreeScene& geometry() const { return geometry_; }
  const LightSampler& lights() const { return lights_; }

 private:
  EmbreeScene geometry_;
  LightSampler lights_;
  bool has_perfect_specular_ = false;
};

// Adds one accepted sample to pixel `pixel`: running means of LV/HV RGB and Welford (double) of
// the HV luminance. The caller has already rejected non-finite samples.
void accumulate_sample(Accumulation& acc, size_t pixel, glm::vec3 lv, glm::vec3 hv);
void resize_accumulation(Accumulation& acc, int width, int height);  // and clear

}  // namespace pxf
