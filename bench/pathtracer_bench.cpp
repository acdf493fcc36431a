#include "bench/pathtracer_bench.h"

#include <algorithm>
#include <cstdio>
#include <sstream>
#include <thread>
#include <vector>

#include <tbb/task_arena.h>

#include "bench/ray_replay.h"
#include "pathtracer/integrator.h"
#include "pathtracer/ray_recorder.h"

namespace pxf {

namespace {

using Clock = BenchClock;

// The next frame of `renderer` with a recorder attached: every ray it hands to Embree.
RayLog record_frame(ProgressiveRenderer& renderer, BenchResult* result) {
  RayRecorder recorder;
  const uint64_t rays_before = renderer.stats().rays;
  renderer.set_ray_recorder(&recorder);
  renderer.add_frame();
  renderer.set_ray_recorder(nullptr);
  result->recorded_frame_rays = renderer.stats().rays - rays_before;
  RayLog log = recorder.take();
  result->recorded_closest_rays = log.closest_rays();
  result->recorded_shadow_rays = log.shadow_rays();
  result->recorded_stream_rays = log.ray_count(RayQuery::ClosestStream) + log.ray_count(RayQuery::ShadowStream);
  return log;
}

// The tracer's timed frames, run in blocks between the replays: paths/s and rays/s over the
// blocks' wall time, and the median frame time.
class FrameTimer {
 public:
  explicit FrameTimer(ProgressiveRenderer& renderer) : renderer_(renderer), before_(renderer.stats()) {}
  void run(int frames) {
    const auto start = Clock::now();
    for (int i = 0; i < frames; ++i) {
      renderer_.add_frame();
      frame_ms_.push_back(renderer_.stats().last_frame_ms);
    }
    total_ms_ += elapsed_ms(start);
  }
  void finish(BenchResult* result) const {
    const double total_s = total_ms_ / 1000.0;
    const uint64_t paths = renderer_.stats().paths - before_.paths, rays = renderer_.stats().rays - before_.rays;
    result->paths_per_s = total_s > 0 ? paths / total_s : 0.0;
    result->rays_per_s = total_s > 0 ? rays / total_s : 0.0;
    result->rays_per_path = paths ? static_cast<double>(rays) / paths : 0.0;
    result->median_frame_ms = median_of(frame_ms_);
  }

 private:
  ProgressiveRenderer& renderer_;
  const TraceStats before_;
  std::vector<double> frame_ms_;
  double total_ms_ = 0;
};

// Raw Embree on the recorded rays (bench/ray_replay.h) on the tracer's scene and threads: the
// closest-hit and the shadow calls timed apart, each one ray per call and as traced.
class ReplayTimer {
 public:
  ReplayTimer(const RayLog& log, RTCScene scene, int threads)
      : log_(log), scene_(scene), arena_(threads > 0 ? threads : tbb::task_arena::automatic),
        closest_calls_(calls_of_kind(log, false)), shadow_calls_(calls_of_kind(log, true)), answers_(log.rays.size()) {}

  // An untimed pass as traced (it also warms the caches): the answers that differ from the tracer's.
  uint64_t mismatches() {
    replay_calls(arena_, scene_, log_, closest_calls_, ReplayCalls::AsTraced, &answers_);
    replay_calls(arena_, scene_, log_, shadow_calls_, ReplayCalls::AsTraced, &answers_);
    uint64_t differing = 0;
    for (size_t i = 0; i < answers_.size(); ++i) differing += !(answers_[i] == log_.answers[i]);
    return differing;
  }
  // One timed repetition: each kind of call in each way.
  void repeat() {
    for (int m = 0; m < 2; ++m) {
      closest_ms_[m].push_back(replay_calls(arena_, scene_, log_, closest_calls_, kModes[m], &answers_));
      shadow_ms_[m].push_back(replay_calls(arena_, scene_, log_, shadow_calls_, kModes[m], &answers_));
    }
  }
  // The rates from the medians of the repetitions.
  void finish(BenchResult* result) const {
    EmbreeReplayRate* rates[] = {&result->embree_single, &result->embree_as_traced};
    for (int m = 0; m < 2; ++m) {
      const double closest_s = median_of(closest_ms_[m]) / 1000.0, shadow_s = median_of(shadow_ms_[m]) / 1000.0;
      rates[m]->closest_rays_per_s = closest_s > 0 ? log_.closest_rays() / closest_s : 0.0;
      rates[m]->shadow_rays_per_s = shadow_s > 0 ? log_.shadow_rays() / shadow_s : 0.0;
      rates[m]->rays_per_s = closest_s + shadow_s > 0 ? log_.rays.size() / (closest_s + shadow_s) : 0.0;
    }
    result->replay_repetitions = static_cast<int>(closest_ms_[0].size());
  }

 private:
  static constexpr ReplayCalls kModes[2] = {ReplayCalls::SingleRays, ReplayCalls::AsTraced};
  const RayLog& log_;
  RTCScene scene_;
  tbb::task_arena arena_;
  const std::vector<uint32_t> closest_calls_, shadow_calls_;
  std::vector<RecordedAnswer> answers_;
  std::vector<double> closest_ms_[2], shadow_ms_[2];  // per mode, one per repetition
};

double fraction(double part, double whole) { return whole > 0 ? part / whole : 0.0; }

// Primary rays as the integrator makes them: frames cut to 2 vertices (camera rays, their first
// hits and the emission found there); the median of `frames` after one warm-up.
double primary_ray_ms(const Scene& scene, const TraceParams& params, int width, int height, int frames) {
  TraceParams primary_params = params;
  primary_params.max_vertices = 2;
  ProgressiveRenderer primary(scene, primary_params, width, height);
  primary.add_frame();
  std::vector<double> ms;
  for (int i = 0; i < frames; ++i) {
    primary.add_frame();
    ms.push_back(primary.stats().last_frame_ms);
  }
  return median_of(ms);
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
  const RayLog log = record_frame(renderer, &result);
  // The timed frames in `repetitions` blocks, each followed by one replay: a shared machine's
  // drift then slows the tracer and raw Embree alike, and the fraction stays meaningful.
  const int repetitions = std::max(5, timed / 4);
  ReplayTimer replay(log, renderer.tracer().geometry().handle(), params.threads);
  result.replay_mismatches = replay.mismatches();
  FrameTimer frames(renderer);
  for (int rep = 0; rep < repetitions; ++rep) {
    frames.run(timed * (rep + 1) / repetitions - timed * rep / repetitions);
    replay.repeat();
  }
  frames.finish(&result);
  replay.finish(&result);
  result.fraction_of_embree_single = fraction(result.rays_per_s, result.embree_single.rays_per_s);
  result.fraction_of_embree_as_traced = fraction(result.rays_per_s, result.embree_as_traced.rays_per_s);
  result.primary_ray_ms = primary_ray_ms(scene, params, width, height, repetitions);
  result.primary_fraction = fraction(result.primary_ray_ms, result.median_frame_ms);
  return result;
}

std::string format_benchmark(const BenchResult& r) {
  const double recorded = static_cast<double>(r.recorded_closest_rays + r.recorded_shadow_rays);
  const auto rate = [](const EmbreeReplayRate& e) {
    char text[160];
    std::snprintf(text, sizeof text, "%.2f M rays/s (closest-hit %.2f, shadow %.2f)", e.rays_per_s * 1e-6,
                  e.closest_rays_per_s * 1e-6, e.shadow_rays_per_s * 1e-6);
    return std::string(text);
  };
  char buffer[1024];
  std::snprintf(buffer, sizeof buffer,
                "%dx%d, %d threads, %d vertices, %d frames: %.2f M paths/s, %.2f M rays/s (%.2f rays/path), "
                "median %.2f ms/frame; primary rays %.2f ms (%.0f%% of a frame)\n"
                "raw Embree on the same rays: the frame after the warm-up recorded, %.3f M rays (%.0f%% closest-hit, "
                "%.0f%% shadow; %.0f%% in streams), replayed on the same scene and threads, median of %d:\n"
                "  as traced (its streams as streams of the same sizes): %s; the tracer %.0f%% of it\n"
                "  one ray per call (rtcIntersect1 / rtcOccluded1):      %s; the tracer %.0f%% of it",
                r.width, r.height, r.threads, r.max_vertices, r.timed_frames, r.paths_per_s * 1e-6, r.rays_per_s * 1e-6,
                r.rays_per_path, r.median_frame_ms, r.primary_ray_ms, 100.0 * r.primary_fraction, recorded * 1e-6,
                100.0 * fraction(r.recorded_closest_rays, recorded), 100.0 * fraction(r.recorded_shadow_rays, recorded),
                100.0 * fraction(r.recorded_stream_rays, recorded), r.replay_repetitions, rate(r.embree_as_traced).c_str(),
                100.0 * r.fraction_of_embree_as_traced, rate(r.embree_single).c_str(), 100.0 * r.fraction_of_embree_single);
  std::string text = buffer;
  if (r.replay_mismatches > 0)
    text += "\n  warning: " + std::to_string(r.replay_mismatches) + " replayed answers differ from the tracer's";
  if (recorded != static_cast<double>(r.recorded_frame_rays))
    text += "\n  note: the frame counted " + std::to_string(r.recorded_frame_rays) +
            " rays; the rest of those recorded are guiding's photons";
  return text;
}

std::string benchmark_csv(const BenchResult& r) {
  std::ostringstream csv;
  csv << "width,height,threads,max_vertices,timed_frames,paths_per_s,rays_per_s,rays_per_path,median_frame_ms,"
         "recorded_closest_rays,recorded_shadow_rays,recorded_stream_rays,recorded_frame_rays,replay_repetitions,"
         "embree_single_rays_per_s,embree_single_closest_rays_per_s,embree_single_shadow_rays_per_s,"
         "fraction_of_embree_single,embree_as_traced_rays_per_s,embree_as_traced_closest_rays_per_s,"
         "embree_as_traced_shadow_rays_per_s,fraction_of_embree_as_traced,replay_mismatches,primary_ray_ms,"
         "primary_fraction\n";
  csv << r.width << "," << r.height << "," << r.threads << "," << r.max_vertices << "," << r.timed_frames << ","
      << r.paths_per_s << "," << r.rays_per_s << "," << r.rays_per_path << "," << r.median_frame_ms << ","
      << r.recorded_closest_rays << "," << r.recorded_shadow_rays << "," << r.recorded_stream_rays << ","
      << r.recorded_frame_rays << "," << r.replay_repetitions << "," << r.embree_single.rays_per_s << ","
      << r.embree_single.closest_rays_per_s << "," << r.embree_single.shadow_rays_per_s << ","
      << r.fraction_of_embree_single << "," << r.embree_as_traced.rays_per_s << ","
      << r.embree_as_traced.closest_rays_per_s << "," << r.embree_as_traced.shadow_rays_per_s << ","
      << r.fraction_of_embree_as_traced << "," << r.replay_mismatches << "," << r.primary_ray_ms << ","
      << r.primary_fraction << "\n";
  return csv.str();
}

}  // namespace pxf
