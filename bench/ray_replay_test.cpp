// The same-ray replay of `pxf bench pathtracer` (bench/ray_replay.h): raw Embree, given the
// recorded frame's rays, answers them as it answered the tracer (closest hits: mesh, triangle and
// t; shadow rays: occluded), one by one and as the tracer's own streams; and the bench's figures
// are consistent (no wall-time asserts: the rates are only checked to exist).
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "bench/pathtracer_bench.h"
#include "bench/ray_replay.h"
#include "pathtracer/integrator.h"
#include "testing/shapes.h"

namespace pxf {
namespace {

RayLog record_second_frame(ProgressiveRenderer& renderer) {
  renderer.add_frame();
  RayRecorder recorder;
  renderer.set_ray_recorder(&recorder);
  renderer.add_frame();
  renderer.set_ray_recorder(nullptr);
  return recorder.take();
}

TEST(RayReplay, RawEmbreeGivesTheTracersAnswersOnTheRecordedRays) {
  const Scene scenes[] = {make_cornell_with_veil(), make_room_with_window()};
  for (const Scene& scene : scenes) {
    TraceParams params;
    params.threads = 2;
    ProgressiveRenderer renderer(scene, params, 48, 40);
    const RayLog log = record_second_frame(renderer);
    ASSERT_GT(log.closest_rays(), 0u);
    ASSERT_GT(log.shadow_rays(), 0u);
    tbb::task_arena arena(2);
    const RTCScene handle = renderer.tracer().geometry().handle();
    for (ReplayCalls how : {ReplayCalls::AsTraced, ReplayCalls::SingleRays}) {
      // Filled with an answer Embree never gives, so that a ray the replay skipped shows.
      std::vector<RecordedAnswer> answers(log.rays.size(), RecordedAnswer{7u, 7u, -1.0f, true});
      replay_calls(arena, handle, log, calls_of_kind(log, false), how, &answers);
      replay_calls(arena, handle, log, calls_of_kind(log, true), how, &answers);
      size_t differing = 0, hits = 0, blocked = 0;
      for (size_t i = 0; i < answers.size(); ++i) {
        differing += !(answers[i] == log.answers[i]);
        hits += answers[i].mesh != RTC_INVALID_GEOMETRY_ID;
        blocked += answers[i].occluded;
      }
      EXPECT_EQ(differing, 0u) << (how == ReplayCalls::AsTraced ? "as traced" : "single rays");
      EXPECT_GT(hits, 0u);
      EXPECT_GT(blocked, 0u);
    }
  }
}

// Replaying only the shadow calls leaves the closest-hit rays' answers alone, and the reverse.
TEST(RayReplay, ReplaysOnlyTheCallsItIsGiven) {
  const Scene scene = make_cornell_with_veil();
  TraceParams params;
  params.threads = 1;
  ProgressiveRenderer renderer(scene, params, 24, 24);
  const RayLog log = record_second_frame(renderer);
  tbb::task_arena arena(1);
  const RecordedAnswer untouched{7u, 7u, -1.0f, true};
  std::vector<RecordedAnswer> answers(log.rays.size(), untouched);
  replay_calls(arena, renderer.tracer().geometry().handle(), log, calls_of_kind(log, true), ReplayCalls::AsTraced,
               &answers);
  for (const RecordedCall& call : log.calls)
    for (uint32_t i = call.first; i < call.first + call.count; ++i)
      EXPECT_EQ(answers[i] == untouched, !is_shadow_query(call.query)) << "ray " << i;
}

// The bench on a tiny image: the recorded frame's rays are the frame's counted rays, raw Embree
// answered all of them as it answered the tracer, every rate is there, and the CSV's header and
// row have as many columns.
TEST(RayReplay, TheBenchReplaysTheRecordedFrame) {
  const Scene scene = make_cornell_with_veil();
  TraceParams params;
  params.threads = 2;
  const BenchResult r = run_benchmark(scene, 32, 24, params, 1, 2);
  EXPECT_EQ(r.recorded_closest_rays + r.recorded_shadow_rays, r.recorded_frame_rays);
  EXPECT_GT(r.recorded_shadow_rays, 0u);
  EXPECT_LE(r.recorded_stream_rays, r.recorded_frame_rays);
  EXPECT_EQ(r.replay_mismatches, 0u);
  EXPECT_EQ(r.replay_repetitions, 5);
  for (double rate : {r.embree_single.rays_per_s, r.embree_single.closest_rays_per_s, r.embree_single.shadow_rays_per_s,
                      r.embree_as_traced.rays_per_s, r.embree_as_traced.closest_rays_per_s,
                      r.embree_as_traced.shadow_rays_per_s, r.fraction_of_embree_single, r.fraction_of_embree_as_traced})
    EXPECT_GT(rate, 0.0);
  const std::string csv = benchmark_csv(r);
  const size_t newline = csv.find('\n');
  ASSERT_NE(newline, std::string::npos);
  const std::string header = csv.substr(0, newline), row = csv.substr(newline + 1);
  EXPECT_EQ(std::count(header.begin(), header.end(), ','), std::count(row.begin(), row.end(), ','));
  EXPECT_NE(header.find("fraction_of_embree_as_traced"), std::string::npos);
}

}  // namespace
}  // namespace pxf
