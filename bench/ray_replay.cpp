#include "bench/ray_replay.h"

#include <algorithm>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/timing.h"

namespace pxf {

namespace {

// The longest stream call EmbreeScene makes (its kStreamChunk); a longer one is replayed in pieces.
constexpr size_t kMaxStream = 64;
// Calls per task: a task then holds a few thousand rays, as one of the tracer's tiles does.
constexpr size_t kCallsPerTask = 64;

RTCIntersectContext context_for(RayCoherence coherence) {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = coherence == RayCoherence::Coherent ? RTC_INTERSECT_CONTEXT_FLAG_COHERENT
                                                      : RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
  return context;
}

RTCRay rtc_ray(const RecordedRay& ray) {
  RTCRay r;
  r.org_x = ray.origin.x;
  r.org_y = ray.origin.y;
  r.org_z = ray.origin.z;
  r.tnear = ray.tmin;
  r.dir_x = ray.direction.x;
  r.dir_y = ray.direction.y;
  r.dir_z = ray.direction.z;
  r.time = 0.0f;
  r.tfar = ray.tmax;
  r.mask = 0xffffffffu;
  r.id = 0;
  r.flags = 0;
  return r;
}

RTCRayHit rtc_ray_hit(const RecordedRay& ray) {
  RTCRayHit rh;
  rh.ray = rtc_ray(ray);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  return rh;
}

// As the tracer reads an answer (EmbreeScene's hit_of and is_occluded).
RecordedAnswer closest_answer(const RTCRayHit& rh) {
  RecordedAnswer a;
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return a;
  a.mesh = rh.hit.geomID;
  a.prim = rh.hit.primID;
  a.t = rh.ray.tfar;
  return a;
}

RecordedAnswer shadow_answer(const RTCRay& r) {
  RecordedAnswer a;
  a.occluded = r.tfar < 0.0f;
  return a;
}

void replay_single(RTCScene scene, const RecordedCall& call, const RecordedRay* rays, RecordedAnswer* answers) {
  RTCIntersectContext context = context_for(call.coherence);
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
  RTCIntersectContext context = context_for(call.coherence);
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
