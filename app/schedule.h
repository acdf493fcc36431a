// When the (expensive) cross bilateral filter runs (SPEC 3.5). The blend and tone map run every
// displayed frame with the newest L_f; the filter only on this schedule.
#pragma once
#include <string>
#include <vector>

namespace pxf {

enum class FilterSchedule { PowersOfTwo, EveryFrame };
const std::vector<std::string>& filter_schedule_names();  // "pow2", "every"
FilterSchedule parse_filter_schedule(const std::string& name);

struct ScheduleState {
  bool hv_empty = true;          // no HV radiance yet anywhere (e.g. a scene lit only directly)
  bool all_pixels_case2 = false; // every pixel already meets the threshold unfiltered
  bool have_filtered = false;    // an L_f exists from an earlier run
};

// Whether the filter runs after the frame that brought the sample count to `samples`.
bool filter_due(FilterSchedule schedule, int samples, bool last_frame, const ScheduleState& state);

}  // namespace pxf
