#include "bench/pathtracer_bench.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <thread>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "pathtracer/integrator.h"
#include "pathtracer/rng.h"
#include "pathtracer/sampling.h"

namespace pxf {

namespace {

using Clock = BenchClock;
constexpr size_t kStreamRays = 256;  // rays per call of the stream ceiling: one integrator batch

// Incoherent rays as a path tracer makes them: from first hits, cosine-distributed around the
// shading normal (one per pixel), falling back to camera rays where the camera sees nothing.
std::vector<Ray> incoherent_rays(const PathTracer& tracer, const Camera& camera, int width, int height) {
  std::vector<Ray> rays;
  rays.reserve(static_cast<size_t>(width) * height);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      Rng rng(7, static_cast<uint64_t>(y) * width + x, 0);
      glm::vec2 j = rng.next_2d();
      Ray ray = camera_ray(camera, width, height, x + j.x, y + j.y);
      Hit hit = tracer.geometry().intersect(ray);
      if (hit.valid()) {
        SurfacePoint sp = tracer.geometry().surface_point(hit, ray);
        glm::vec3 n = sp.front_face ? sp.geometric_normal : -sp.geometric_normal;
        glm::vec3 d = Frame::from_normal(n).to_world(sample_cosine_hemisphere(rng.next_2d()));
        ray.origin = offset_ray_origin(sp.position, n, d);
        ray.direction = glm::normalize(d);
      }
      rays.push_back(ray);
    }
  }
  return rays;
}

// Runs body(range) over [0, count) on the arena's threads; the body counts hits in a local and
// adds them to `hits` once per range (one shared atomic per ray would make the threads fight over
// its cache line and understate Embree's rate).
template <typename Body>
double timed_parallel_ms(tbb::task_arena& arena, size_t count, size_t grain, std::atomic<uint64_t>& hits,
                         const Body& body) {
  auto start = Clock::now();
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, count, grain), [&](const tbb::blocked_range<size_t>& r) {
      hits.fetch_add(body(r.begin(), r.end()), std::memory_order_relaxed);
    });
  });
  return elapsed_ms(start);
}

}  // namespace

BenchResult run_benchmark(const Scene& scene, int width, int height, const TraceParams& params, int warmup, int timed) {
  BenchResult result;
  result.width = width;
  result.height = height;
  result.max_vertices = params.max_vertices;
  result.threads = params.threads > 0 ? params.threads : static_cast<int>(std::thread::hardware_concurrency());
  result.timed_frames = timed;
  ProgressiveRenderer renderer(scene, params, width, height);
  for (int i = 0; i < warmup; ++i) renderer.add_frame();
  TraceStats before = renderer.stats();
  std::vector<double> frame_ms;
  auto start = Clock::now();
  for (int i = 0; i < timed; ++i) {
    renderer.add_frame();
    frame_ms.push_back(renderer.stats().last_frame_ms);
  }
  double total_s = elapsed_ms(start) / 1000.0;
  uint64_t paths = renderer.stats().paths - before.paths, rays = renderer.stats().rays - before.rays;
  result.paths_per_s = paths / total_s;
  result.rays_per_s = rays / total_s;
  result.rays_per_path = paths ? static_cast<double>(rays) / paths : 0.0;
  result.median_frame_ms = median_of(frame_ms);

  // The ceiling: Embree alone on incoherent rays of this scene, on the same number of threads,
  // one rtcIntersect1 per ray; and the same rays as streams, as the integrator sends them.
  PathTracer tracer(renderer.scene());
  const EmbreeScene& geometry = tracer.geometry();
  tbb::task_arena arena(params.threads > 0 ? params.threads : tbb::task_arena::automatic);
  const std::vector<Ray> rays_in = incoherent_rays(tracer, renderer.camera(), width, height);
  std::atomic<uint64_t> hits{0};
  std::vector<double> single_ms, stream_ms;
  for (int i = 0; i < std::max(5, timed / 4); ++i) {
    single_ms.push_back(timed_parallel_ms(arena, rays_in.size(), 1024, hits, [&](size_t begin, size_t end) {
      uint64_t n = 0;
      for (size_t k = begin; k != end; ++k) n += geometry.intersect(rays_in[k]).valid();
      return n;
    }));
    stream_ms.push_back(timed_parallel_ms(arena, rays_in.size(), 1024, hits, [&](size_t begin, size_t end) {
      Hit stream_hits[kStreamRays];
      uint64_t n = 0;
      for (size_t first = begin; first < end; first += kStreamRays) {
        const size_t count = std::min(kStreamRays, end - first);
        geometry.intersect(&rays_in[first], count, RayCoherence::Incoherent, stream_hits);
        for (size_t k = 0; k < count; ++k) n += stream_hits[k].valid();
      }
      return n;
    }));
  }
  result.embree_rays_per_s = rays_in.size() / (median_of(single_ms) / 1000.0);
  result.fraction_of_embree = result.rays_per_s / result.embree_rays_per_s;
  result.embree_stream_rays_per_s = rays_in.size() / (median_of(stream_ms) / 1000.0);
  result.fraction_of_embree_stream = result.rays_per_s / result.embree_stream_rays_per_s;

  // Primary rays as the integrator makes them: the same frames cut to 2 vertices (camera rays,
  // their first hits and the emission found there).
  TraceParams primary_params = params;
  primary_params.max_vertices = 2;
  ProgressiveRenderer primary(scene, primary_params, width, height);
  primary.add_frame();  // warm-up
  std::vector<double> primary_ms;
  for (int i = 0; i < std::max(5, timed / 4); ++i) {
    primary.add_frame();
    primary_ms.push_back(primary.stats().last_frame_ms);
  }
  result.primary_ray_ms = median_of(primary_ms);
  result.primary_fraction = result.primary_ray_ms / result.median_frame_ms;
  return result;
}

std::string format_benchmark(const BenchResult& r) {
  char buffer[512];
  std::snprintf(buffer, sizeof buffer,
                "%dx%d, %d threads, %d vertices, %d frames: %.2f M paths/s, %.2f M rays/s (%.2f rays/path), "
                "median %.2f ms/frame; raw Embree %.2f M rays/s (%.0f%%), as streams %.2f M rays/s (%.0f%%); "
                "primary rays %.2f ms (%.0f%% of a frame)",
                r.width, r.height, r.threads, r.max_vertices, r.timed_frames, r.paths_per_s * 1e-6, r.rays_per_s * 1e-6,
                r.rays_per_path, r.median_frame_ms, r.embree_rays_per_s * 1e-6, 100.0 * r.fraction_of_embree,
                r.embree_stream_rays_per_s * 1e-6, 100.0 * r.fraction_of_embree_stream, r.primary_ray_ms,
                100.0 * r.primary_fraction);
  return buffer;
}

}  // namespace pxf
