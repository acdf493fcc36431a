#include "app/schedule.h"

#include "image/image.h"

namespace pxf {

const std::vector<std::string>& filter_schedule_names() {
  static const std::vector<std::string> names = {"pow2", "every"};
  return names;
}

FilterSchedule parse_filter_schedule(const std::string& name) {
  if (name == "pow2") return FilterSchedule::PowersOfTwo;
  if (name == "every") return FilterSchedule::EveryFrame;
  throw Error("unknown filter schedule '" + name + "'");
}

bool filter_due(FilterSchedule schedule, int samples, bool last_frame, const ScheduleState& state) {
  if (samples < 1 || state.hv_empty || state.all_pixels_case2) return false;
  if (last_frame || schedule == FilterSchedule::EveryFrame) return true;
  return (samples & (samples - 1)) == 0;
}

}  // namespace pxf
