#include "pathtracer/bench.h"

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

double median_of(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

namespace {

using Clock = BenchClock;

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

template <typename Body>
double timed_parallel_ms(tbb::task_arena& arena, size_t count, const Body& body) {
  auto start = Clock::now();
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, count, 1024), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t i = r.begin(); i != r.end(); ++i) body(i);
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

  PathTracer tracer(renderer.scene());
  const Camera& camera = renderer.camera();
  tbb::task_arena arena(params.threads > 0 ? params.threads : tbb::task_arena::automatic);
  std::vector<Ray> rays_in = incoherent_rays(tracer, camera, width, height);
  std::atomic<uint64_t> sink{0};
  std::vector<double> embree_ms, primary_ms;
  for (int i = 0; i < std::max(5, timed / 4); ++i) {
    embree_ms.push_back(timed_parallel_ms(arena, rays_in.size(), [&](size_t k) {
      if (tracer.geometry().intersect(rays_in[k]).valid()) sink.fetch_add(0, std::memory_order_relaxed);
    }));
    // Primary rays as the integrator makes them: jitter, camera_ray, intersect, surface point.
    primary_ms.push_back(timed_parallel_ms(arena, static_cast<size_t>(width) * height, [&](size_t k) {
      int x = static_cast<int>(k % width), y = static_cast<int>(k / width);
      Rng rng(params.seed, k, static_cast<uint64_t>(i));
      glm::vec2 j = rng.next_2d();
      Ray ray = camera_ray(camera, width, height, x + j.x, y + j.y);
      Hit hit = tracer.geometry().intersect(ray);
      if (hit.valid() && tracer.geometry().surface_point(hit, ray).front_face) sink.fetch_add(0, std::memory_order_relaxed);
    }));
  }
  result.embree_rays_per_s = rays_in.size() / (median_of(embree_ms) / 1000.0);
  result.fraction_of_embree = result.rays_per_s / result.embree_rays_per_s;
  result.primary_ray_ms = median_of(primary_ms);
  result.primary_fraction = result.primary_ray_ms / result.median_frame_ms;
  return result;
}

std::string format_benchmark(const BenchResult& r) {
  char buffer[512];
  std::snprintf(buffer, sizeof buffer,
                "%dx%d, %d threads, %d vertices, %d frames: %.2f M paths/s, %.2f M rays/s (%.2f rays/path), "
                "median %.2f ms/frame; raw Embree %.2f M rays/s (%.0f%%); primary rays %.2f ms (%.0f%% of a frame)",
                r.width, r.height, r.threads, r.max_vertices, r.timed_frames, r.paths_per_s * 1e-6, r.rays_per_s * 1e-6,
                r.rays_per_path, r.median_frame_ms, r.embree_rays_per_s * 1e-6, 100.0 * r.fraction_of_embree,
                r.primary_ray_ms, 100.0 * r.primary_fraction);
  return buffer;
}

}  // namespace pxf
