// Path tracer throughput benchmark (the front end prints it): paths/s and rays/s over timed
// frames, against the raw Embree rate for incoherent rays on the same scene, plus the share of a
// frame spent on primary rays (what reusing the raster's first hit could save at most).
#pragma once
#include <string>
#include "core/timing.h"
#include "pathtracer/pathtracer.h"

namespace pxf {

struct BenchResult {
  int width = 0, height = 0, threads = 0, max_vertices = 0;
  int timed_frames = 0;
  double paths_per_s = 0;
  double rays_per_s = 0;
  double rays_per_path = 0;
  double median_frame_ms = 0;
  double embree_rays_per_s = 0;         // rtcIntersect1 on incoherent rays of the scene, same threads
  double fraction_of_embree = 0;        // rays_per_s / embree_rays_per_s (how close the tracer comes to raw Embree)
  double embree_stream_rays_per_s = 0;  // the same rays as rtcIntersect1M streams of 256
  double fraction_of_embree_stream = 0; // rays_per_s / embree_stream_rays_per_s
  double primary_ray_ms = 0;            // median time of a frame cut to camera rays and first hits
  double primary_fraction = 0;        // primary_ray_ms / median_frame_ms
};

// Renders `warmup` frames, then `timed` (>= 20 recommended) frames of `scene` at width x height.
BenchResult run_benchmark(const Scene& scene, int width, int height, const TraceParams& params, int warmup = 3,
                          int timed = 20);
std::string format_benchmark(const BenchResult& result);

}  // namespace pxf
