// The ray recorder (pathtracer/ray_recorder.h): it logs each of EmbreeScene's four queries as
// Embree got it, with the answer; over a frame it logs as many rays as the frame's TraceStats
// count; and attaching it changes nothing in the image.
#include <gtest/gtest.h>

#include <limits>
#include <string>
#include <vector>

#include "pathtracer/integrator.h"
#include "pathtracer/ray_recorder.h"
#include "testing/same_bits.h"
#include "testing/shapes.h"

namespace pxf {
namespace {

TraceParams two_threads() {
  TraceParams params;
  params.threads = 2;
  return params;
}

// A unit box around the origin, seen from inside; the four queries, one after another.
TEST(RayRecorder, LogsEachQueryAsEmbreeGotItWithItsAnswer) {
  Scene scene;
  scene.materials = {make_diffuse(glm::vec3(0.5f))};
  scene.meshes.push_back(make_box(glm::vec3(-1.0f), glm::vec3(1.0f), 0));
  EmbreeScene geometry(scene);
  RayRecorder recorder;
  geometry.set_ray_recorder(&recorder);

  const Ray single{glm::vec3(0.0f), glm::vec3(1, 0, 0)};
  const Hit single_hit = geometry.intersect(single, 5.0f);
  std::vector<Ray> stream(100);  // 64 + 36: EmbreeScene's chunks are separate Embree calls
  for (size_t i = 0; i < stream.size(); ++i)
    stream[i] = Ray{glm::vec3(0.0f), glm::normalize(glm::vec3(1.0f, 0.01f * i - 0.5f, 0.2f))};
  std::vector<Hit> stream_hits(stream.size());
  geometry.intersect(stream.data(), stream.size(), RayCoherence::Coherent, stream_hits.data());
  const bool blocked = geometry.occluded(glm::vec3(0.0f), glm::vec3(0, 1, 0), 2.0f);
  const ShadowRay shadows[] = {{glm::vec3(0.0f), glm::vec3(0, 0, 1), 0.5f}, {glm::vec3(0.0f), glm::vec3(0, 0, -1), 3.0f}};
  bool shadow_blocked[2];
  geometry.occluded(shadows, 2, shadow_blocked);
  geometry.set_ray_recorder(nullptr);
  geometry.intersect(single);  // detached: not logged

  const RayLog log = recorder.take();
  ASSERT_EQ(log.calls.size(), 5u);
  ASSERT_EQ(log.rays.size(), 1u + 100u + 1u + 2u);
  ASSERT_EQ(log.answers.size(), log.rays.size());
  EXPECT_EQ(log.calls[0].query, RayQuery::ClosestSingle);
  EXPECT_EQ(log.calls[1].query, RayQuery::ClosestStream);
  EXPECT_EQ(log.calls[1].count, 64u);
  EXPECT_EQ(log.calls[1].coherence, RayCoherence::Coherent);
  EXPECT_EQ(log.calls[2].query, RayQuery::ClosestStream);
  EXPECT_EQ(log.calls[2].count, 36u);
  EXPECT_EQ(log.calls[2].first, 65u);
  EXPECT_EQ(log.calls[3].query, RayQuery::ShadowSingle);
  EXPECT_EQ(log.calls[4].query, RayQuery::ShadowStream);
  EXPECT_EQ(log.calls[4].count, 2u);

  EXPECT_EQ(log.rays[0].tmax, 5.0f);
  EXPECT_EQ(log.rays[0].direction, single.direction);
  EXPECT_EQ(log.answers[0].mesh, single_hit.mesh);
  EXPECT_EQ(log.answers[0].t, single_hit.t);
  EXPECT_FLOAT_EQ(single_hit.t, 1.0f);
  for (size_t i = 0; i < stream.size(); ++i) {
    EXPECT_EQ(log.rays[1 + i].direction, stream[i].direction);
    EXPECT_EQ(log.rays[1 + i].tmax, std::numeric_limits<float>::infinity());
    EXPECT_EQ(log.answers[1 + i].prim, stream_hits[i].prim);
    EXPECT_EQ(log.answers[1 + i].t, stream_hits[i].t);
  }
  EXPECT_EQ(log.rays[101].tmax, 2.0f);
  EXPECT_EQ(log.answers[101].occluded, blocked);
  EXPECT_TRUE(blocked);
  EXPECT_EQ(log.rays[102].tmax, 0.5f);
  EXPECT_FALSE(log.answers[102].occluded);
  EXPECT_TRUE(log.answers[103].occluded);
  for (const RecordedRay& ray : log.rays) EXPECT_EQ(ray.tmin, 0.0f);
  EXPECT_TRUE(recorder.take().rays.empty());  // take() empties the recorder
}

// The recorded frame's rays are the frame's TraceStats rays, one for one: camera, continuation,
// shadow and specular-chain rays, on a box with glass, mirror and a veil and in a room lit
// through a window (light through openings learning from the shadow rays).
TEST(RayRecorder, RecordsAsManyRaysAsTheFrameCounts) {
  const Scene scenes[] = {make_cornell_with_veil(), make_room_with_window()};
  for (const Scene& scene : scenes) {
    ProgressiveRenderer renderer(scene, two_threads(), 48, 40);
    renderer.add_frame();
    RayRecorder recorder;
    const uint64_t before = renderer.stats().rays;
    renderer.set_ray_recorder(&recorder);
    renderer.add_frame();
    renderer.set_ray_recorder(nullptr);
    const uint64_t counted = renderer.stats().rays - before;
    renderer.add_frame();  // detached: nothing more is logged
    const RayLog log = recorder.take();
    EXPECT_EQ(log.rays.size(), counted);
    EXPECT_EQ(log.closest_rays() + log.shadow_rays(), counted);
    EXPECT_GE(log.ray_count(RayQuery::ClosestStream), 48u * 40u);  // at least the camera rays
    EXPECT_GT(log.ray_count(RayQuery::ShadowStream), 0u);
    for (const RecordedCall& call : log.calls) EXPECT_LE(call.first + call.count, log.rays.size());
  }
}

// The single-ray queries of the specular chains are in the log too (the box's glass sphere is
// near enough to the floor for chains from the first diffuse vertex).
TEST(RayRecorder, RecordsTheSpecularChainsSingleRays) {
  const Scene scene = make_cornell_with_veil();
  ProgressiveRenderer renderer(scene, two_threads(), 48, 40);
  RayRecorder recorder;
  renderer.set_ray_recorder(&recorder);
  renderer.add_frame();
  renderer.set_ray_recorder(nullptr);
  EXPECT_GT(recorder.take().ray_count(RayQuery::ClosestSingle), 0u);
}

// Attached or not, the same seed accumulates the same image, bit for bit.
TEST(RayRecorder, RecordingChangesNothingInTheImage) {
  const Scene scenes[] = {make_cornell_with_veil(), make_room_with_window()};
  for (const Scene& scene : scenes) {
    ProgressiveRenderer plain(scene, two_threads(), 40, 32), recorded(scene, two_threads(), 40, 32);
    RayRecorder recorder;
    for (int frame = 0; frame < 3; ++frame) {
      plain.add_frame();
      recorded.set_ray_recorder(frame == 1 ? nullptr : &recorder);  // detaching between frames too
      recorded.add_frame();
    }
    recorded.set_ray_recorder(nullptr);
    EXPECT_GT(recorder.take().rays.size(), 0u);
    const Accumulation &a = plain.accumulation(), &b = recorded.accumulation();
    EXPECT_TRUE(same_bits(a.lv_mean, b.lv_mean));
    EXPECT_TRUE(same_bits(a.hv_mean, b.hv_mean));
    EXPECT_TRUE(same_bits(a.albedo_mean, b.albedo_mean));
    EXPECT_TRUE(same_bits(a.hv_lum_m2, b.hv_lum_m2));
    EXPECT_TRUE(same_bits(a.samples, b.samples));
    EXPECT_EQ(plain.stats().rays, recorded.stats().rays);
    EXPECT_EQ(plain.environment_visibility(), recorded.environment_visibility());
  }
}

}  // namespace
}  // namespace pxf
