// Ray recording, for `pxf bench pathtracer`: while a RayRecorder is attached to an EmbreeScene
// (ProgressiveRenderer::set_ray_recorder), every query the scene hands to Embree is logged as Embree
// got it (origin, direction, tmin, tmax; single call or stream, coherence flag) with the answer
// the tracer got, so that the bench can replay exactly those rays through raw Embree and compare
// rates on the same work. The tracer queries from TBB worker threads: each thread logs into its
// own buffer, and take() merges them once the frame is done.
#pragma once
#include <cstdint>
#include <vector>
#include <tbb/enumerable_thread_specific.h>
#include "pathtracer/embree_scene.h"

namespace pxf {

// EmbreeScene's four query entry points: closest hit or occlusion (a shadow ray), one ray
// (rtcIntersect1 / rtcOccluded1) or a stream (rtcIntersect1M / rtcOccluded1M).
enum class RayQuery : uint8_t { ClosestSingle, ClosestStream, ShadowSingle, ShadowStream };
inline bool is_shadow_query(RayQuery q) { return q == RayQuery::ShadowSingle || q == RayQuery::ShadowStream; }
inline bool is_stream_query(RayQuery q) { return q == RayQuery::ClosestStream || q == RayQuery::ShadowStream; }

// A ray as Embree got it: hits count in [tmin, tmax].
struct RecordedRay {
  glm::vec3 origin{0.0f};
  float tmin = 0.0f;
  glm::vec3 direction{0.0f};
  float tmax = 0.0f;
};

// What Embree answered the tracer. Closest-hit rays: the hit's mesh (RTC_INVALID_GEOMETRY_ID: a
// miss), triangle and distance; shadow rays: occluded.
struct RecordedAnswer {
  unsigned mesh = RTC_INVALID_GEOMETRY_ID;
  unsigned prim = 0;
  float t = 0.0f;
  bool occluded = false;
  bool operator==(const RecordedAnswer& o) const {
    return mesh == o.mesh && prim == o.prim && t == o.t && occluded == o.occluded;
  }
};

// The answer as logged: of a closest-hit query's hit, and of a shadow ray.
RecordedAnswer answer_of(const Hit& hit);
RecordedAnswer occlusion_answer(bool occluded);

// One Embree call: a single-ray call holds one ray, a stream call the rays of one rtcXxx1M call
// (EmbreeScene cuts a longer query into chunks; each chunk is its own call here).
struct RecordedCall {
  RayQuery query = RayQuery::ClosestSingle;
  RayCoherence coherence = RayCoherence::Incoherent;
  uint32_t first = 0;  // its rays are RayLog::rays[first, first + count)
  uint32_t count = 0;
};

// Recorded calls in the order each thread made them (the threads' logs one after another).
struct RayLog {
  std::vector<RecordedRay> rays;
  std::vector<RecordedAnswer> answers;  // answers[i] belongs to rays[i]
  std::vector<RecordedCall> calls;

  uint64_t ray_count(RayQuery query) const;
  uint64_t closest_rays() const { return ray_count(RayQuery::ClosestSingle) + ray_count(RayQuery::ClosestStream); }
  uint64_t shadow_rays() const { return ray_count(RayQuery::ShadowSingle) + ray_count(RayQuery::ShadowStream); }
  uint64_t call_count(RayQuery query) const;
};

class RayRecorder {
 public:
  // EmbreeScene's queries, after Embree answered. The stream calls take the whole query and the
  // chunk EmbreeScene cut it into, so that the scene pays one branch per query when unattached.
  void closest(const Ray& ray, float tmin, float tmax, const Hit& hit);
  void closest_stream(const Ray* rays, size_t count, size_t chunk, RayCoherence coherence, float tmin, float tmax,
                      const Hit* hits);
  void shadow(glm::vec3 origin, glm::vec3 direction, float tmin, float tmax, bool occluded);
  void shadow_stream(const ShadowRay* rays, size_t count, size_t chunk, float tmin, const bool* occluded);

  // Every thread's log merged into one, and the recorder emptied. Not while a thread records.
  RayLog take();

 private:
  tbb::enumerable_thread_specific<RayLog> logs_;
};

}  // namespace pxf
