// Replays a recorded frame's rays (pathtracer/ray_recorder.h) through raw Embree on the tracer's
// own RTCScene: the throughput bench's yardstick for the tracer's rays/s on exactly its own work.
#pragma once
#include <cstdint>
#include <vector>
#include <embree3/rtcore.h>
#include <tbb/task_arena.h>
#include "pathtracer/ray_recorder.h"

namespace pxf {

enum class ReplayCalls {
  SingleRays,  // every ray by itself: rtcIntersect1 / rtcOccluded1
  AsTraced,    // each recorded call as the tracer made it: a stream as one rtcIntersect1M / rtcOccluded1M
               // of the same rays (its size and coherence flag), a single-ray call as one rtcXxx1
};

// The indices into log.calls of the shadow calls (shadow = true) or of the closest-hit calls.
std::vector<uint32_t> calls_of_kind(const RayLog& log, bool shadow);

// Replays log.calls[i] for each i in `calls` on the arena's threads; (*answers)[r] gets ray r's
// answer (answers has log.rays.size() entries; the rays of other calls are left alone). Returns
// the wall time in ms. The filter functions the scene carries (alpha masks) run as in the tracer.
double replay_calls(tbb::task_arena& arena, RTCScene scene, const RayLog& log, const std::vector<uint32_t>& calls,
                    ReplayCalls how, std::vector<RecordedAnswer>* answers);

}  // namespace pxf
