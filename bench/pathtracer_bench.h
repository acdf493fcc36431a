// Path tracer throughput benchmark (the front end prints it): paths/s and rays/s over timed
// frames; against raw Embree on the same rays (one frame recorded and replayed through Embree alone
// on the tracer's own scene and threads); and the share of a frame spent on primary rays (what
// reusing the raster's first hit could save at most).
#pragma once
#include <cstdint>
#include <string>
#include "core/timing.h"
#include "pathtracer/pathtracer.h"

namespace pxf {

// Raw Embree's rate on the recorded rays, each kind timed by itself (median of the repetitions).
struct EmbreeReplayRate {
  double closest_rays_per_s = 0;  // the closest-hit rays (camera, continuation, specular chains)
  double shadow_rays_per_s = 0;   // the shadow rays
  double rays_per_s = 0;          // all recorded rays over the sum of the two medians
};

struct BenchResult {
  int width = 0, height = 0, threads = 0, max_vertices = 0;
  int timed_frames = 0;
  double paths_per_s = 0;
  double rays_per_s = 0;
  double rays_per_path = 0;
  double median_frame_ms = 0;
  // The frame after the warm-up, recorded (pathtracer/ray_recorder.h): every ray it handed to Embree.
  uint64_t recorded_closest_rays = 0, recorded_shadow_rays = 0;
  uint64_t recorded_stream_rays = 0;  // of those, the rays Embree got in streams (the rest one by one)
  uint64_t recorded_frame_rays = 0;   // TraceStats' rays of that frame (guiding's photons are recorded, not counted)
  // Its rays replayed through Embree alone (bench/ray_replay.h), replay_repetitions times, same threads.
  int replay_repetitions = 0;
  EmbreeReplayRate embree_single;     // every ray by rtcIntersect1 / rtcOccluded1
  EmbreeReplayRate embree_as_traced;  // the tracer's own calls: its streams as rtcIntersect1M / rtcOccluded1M
  double fraction_of_embree_single = 0;     // rays_per_s / embree_single.rays_per_s
  double fraction_of_embree_as_traced = 0;  // rays_per_s / embree_as_traced.rays_per_s
  uint64_t replay_mismatches = 0;  // replayed answers that differ from the tracer's (0: the same work)
  double primary_ray_ms = 0;       // median time of a frame cut to camera rays and first hits
  double primary_fraction = 0;     // primary_ray_ms / median_frame_ms
};

// Renders `warmup` frames and records the next one; then times `timed` (>= 20 recommended) frames
// of `scene` at width x height in max(5, timed / 4) blocks, each followed by one timed replay of
// the recorded rays (replay_repetitions); then primary-ray frames.
BenchResult run_benchmark(const Scene& scene, int width, int height, const TraceParams& params, int warmup = 3,
                          int timed = 20);
std::string format_benchmark(const BenchResult& result);
// The result as CSV: a header line and one row.
std::string benchmark_csv(const BenchResult& result);

}  // namespace pxf
