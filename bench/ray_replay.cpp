#include "bench/ray_replay.h"

#include <algorithm>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/timing.h"
#include "pathtracer/embree_scene.h"

namespace pxf {

namespace {

// The longest stream call EmbreeScene makes; the recorder logs each chunk as its own call.
constexpr size_t kMaxStream = kEmbreeStreamChunk;
// Calls per task: a task then holds a few thousand rays, as one of the tracer's tiles does.
constexpr size_t kCallsPerTask = 64;

RTCRay rtc_ray(const RecordedRay& ray) { return embree_ray(ray.origin, ray.direction, ray.tmax, ray.tmin); }

RTCRayHit rtc_ray_hit(const RecordedRay& ray) { return embree_ray_hit(ray.origin, ray.direction, ray.tmax, ray.tmin); }

// As the tracer reads an answer, and as the recorder logs it.
RecordedAnswer closest_answer(const RTCRayHit& rh) { return answer_of(hit_of(rh)); }

RecordedAnswer shadow_answer(const RTCRay& r) { return occlusion_answer(is_occluded(r)); }

void replay_single(RTCScene scene, const RecordedCall& call, const RecordedRay* rays, RecordedAnswer* answers) {
  RTCIntersectContext context = intersect_context(call.coherence);
  for (uint32_t i = call.first; i < call.first + call.count; ++i) {
    if (is_shadow_query(call.query)) {
      RTCRay r = rtc_ray(rays[i]);
      rtcOccluded1(scene, &context, &r);
      answers[i] = shadow_answer(r);
    } else {
      RTCRayHit rh = rtc_ray_hit(rays[i]);
      rtcIntersect1(scene, &context, &rh);
      answers[i] = closest_answer(rh);
    }
  }
}

void replay_stream(RTCScene scene, const RecordedCall& call, const RecordedRay* rays, RecordedAnswer* answers) {
  RTCIntersectContext context = intersect_context(call.coherence);
  for (uint32_t begin = call.first; begin < call.first + call.count; begin += kMaxStream) {
    const unsigned n = static_cast<unsigned>(std::min<size_t>(kMaxStream, call.first + call.count - begin));
    if (is_shadow_query(call.query)) {
      RTCRay chunk[kMaxStream];
      for (unsigned i = 0; i < n; ++i) chunk[i] = rtc_ray(rays[begin + i]);
      rtcOccluded1M(scene, &context, chunk, n, sizeof(RTCRay));
      for (unsigned i = 0; i < n; ++i) answers[begin + i] = shadow_answer(chunk[i]);
    } else {
      RTCRayHit chunk[kMaxStream];
      for (unsigned i = 0; i < n; ++i) chunk[i] = rtc_ray_hit(rays[begin + i]);
      rtcIntersect1M(scene, &context, chunk, n, sizeof(RTCRayHit));
      for (unsigned i = 0; i < n; ++i) answers[begin + i] = closest_answer(chunk[i]);
    }
  }
}

}  // namespace

std::vector<uint32_t> calls_of_kind(const RayLog& log, bool shadow) {
  std::vector<uint32_t> calls;
  for (size_t i = 0; i < log.calls.size(); ++i)
    if (is_shadow_query(log.calls[i].query) == shadow) calls.push_back(static_cast<uint32_t>(i));
  return calls;
}

double replay_calls(tbb::task_arena& arena, RTCScene scene, const RayLog& log, const std::vector<uint32_t>& calls,
                    ReplayCalls how, std::vector<RecordedAnswer>* answers) {
  if (answers->size() != log.rays.size()) answers->resize(log.rays.size());
  const RecordedRay* rays = log.rays.data();
  RecordedAnswer* out = answers->data();
  const auto start = BenchClock::now();
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, calls.size(), kCallsPerTask), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t k = r.begin(); k != r.end(); ++k) {
        const RecordedCall& call = log.calls[calls[k]];
        if (how == ReplayCalls::AsTraced && is_stream_query(call.query))
          replay_stream(scene, call, rays, out);
        else
          replay_single(scene, call, rays, out);
      }
    });
  });
  return elapsed_ms(start);
}

}  // namespace pxf
