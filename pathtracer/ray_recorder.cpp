#include "pathtracer/ray_recorder.h"

#include <algorithm>

namespace pxf {

RecordedAnswer answer_of(const Hit& hit) {
  RecordedAnswer a;
  a.mesh = hit.mesh;
  a.prim = hit.prim;
  a.t = hit.t;
  return a;
}

RecordedAnswer occlusion_answer(bool occluded) {
  RecordedAnswer a;
  a.occluded = occluded;
  return a;
}

namespace {

// Opens a call of `count` rays at the end of the log.
void open_call(RayLog& log, RayQuery query, RayCoherence coherence, size_t count) {
  log.calls.push_back(RecordedCall{query, coherence, static_cast<uint32_t>(log.rays.size()), static_cast<uint32_t>(count)});
}

}  // namespace

uint64_t RayLog::ray_count(RayQuery query) const {
  uint64_t n = 0;
  for (const RecordedCall& call : calls)
    if (call.query == query) n += call.count;
  return n;
}

uint64_t RayLog::call_count(RayQuery query) const {
  return static_cast<uint64_t>(
      std::count_if(calls.begin(), calls.end(), [&](const RecordedCall& c) { return c.query == query; }));
}

void RayRecorder::closest(const Ray& ray, float tmin, float tmax, const Hit& hit) {
  RayLog& log = logs_.local();
  open_call(log, RayQuery::ClosestSingle, RayCoherence::Incoherent, 1);
  log.rays.push_back(RecordedRay{ray.origin, tmin, ray.direction, tmax});
  log.answers.push_back(answer_of(hit));
}

void RayRecorder::closest_stream(const Ray* rays, size_t count, size_t chunk, RayCoherence coherence, float tmin,
                                 float tmax, const Hit* hits) {
  RayLog& log = logs_.local();
  for (size_t begin = 0; begin < count; begin += chunk) {
    const size_t n = std::min(chunk, count - begin);
    open_call(log, RayQuery::ClosestStream, coherence, n);
    for (size_t i = begin; i < begin + n; ++i) {
      log.rays.push_back(RecordedRay{rays[i].origin, tmin, rays[i].direction, tmax});
      log.answers.push_back(answer_of(hits[i]));
    }
  }
}

void RayRecorder::shadow(glm::vec3 origin, glm::vec3 direction, float tmin, float tmax, bool occluded) {
  RayLog& log = logs_.local();
  open_call(log, RayQuery::ShadowSingle, RayCoherence::Incoherent, 1);
  log.rays.push_back(RecordedRay{origin, tmin, direction, tmax});
  log.answers.push_back(occlusion_answer(occluded));
}

void RayRecorder::shadow_stream(const ShadowRay* rays, size_t count, size_t chunk, float tmin, const bool* occluded) {
  RayLog& log = logs_.local();
  for (size_t begin = 0; begin < count; begin += chunk) {
    const size_t n = std::min(chunk, count - begin);
    open_call(log, RayQuery::ShadowStream, RayCoherence::Incoherent, n);
    for (size_t i = begin; i < begin + n; ++i) {
      log.rays.push_back(RecordedRay{rays[i].origin, tmin, rays[i].direction, rays[i].tmax});
      log.answers.push_back(occlusion_answer(occluded[i]));
    }
  }
}

RayLog RayRecorder::take() {
  RayLog merged;
  for (RayLog& log : logs_) {
    const uint32_t offset = static_cast<uint32_t>(merged.rays.size());
    for (RecordedCall call : log.calls) {
      call.first += offset;
      merged.calls.push_back(call);
    }
    merged.rays.insert(merged.rays.end(), log.rays.begin(), log.rays.end());
    merged.answers.insert(merged.answers.end(), log.answers.begin(), log.answers.end());
  }
  logs_.clear();
  return merged;
}

}  // namespace pxf
