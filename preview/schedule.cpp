#include "preview/schedule.h"

#include <algorithm>

#include "image/image.h"

namespace pxf {

const std::vector<std::string>& filter_schedule_names() {
  static const std::vector<std::string> names = {"pow2", "every", "budget", "final"};
  return names;
}

FilterSchedule parse_filter_schedule(const std::string& name) {
  if (name == "pow2") return FilterSchedule::PowersOfTwo;
  if (name == "every") return FilterSchedule::EveryFrame;
  if (name == "budget") return FilterSchedule::Budget;
  if (name == "final") return FilterSchedule::Final;
  throw Error("unknown filter schedule '" + name + "'");
}

namespace {

bool is_power_of_two(int n) { return n > 0 && (n & (n - 1)) == 0; }

bool run_fits_share(const ScheduleState& s) {
  if (s.last_run_ms <= 0) return true;  // nothing measured yet: this run measures it
  return s.pass_ms + next_run_ms(s) <= kPassShare * s.tracing_ms;
}

}  // namespace

bool filter_due(FilterSchedule schedule, int samples, bool last_frame, const ScheduleState& state) {
  if (samples < 1 || state.hv_empty || state.all_pixels_case2) return false;
  if (last_frame || schedule == FilterSchedule::EveryFrame || state.history_active) return true;
  if (schedule == FilterSchedule::Final) return state.last_run_ms <= 0;  // the first run: its cost
  if (!is_power_of_two(samples)) return false;
  return schedule == FilterSchedule::PowersOfTwo || run_fits_share(state);
}

bool next_frame_fits(const TimeBudget& t) {
  if (t.budget_ms <= 0) return true;
  return t.elapsed_ms + t.next_frame_ms + t.next_pass_ms + t.finish_ms <= t.budget_ms;
}

double predict_frame_ms(const std::vector<double>& recent_frame_ms) {
  if (recent_frame_ms.empty()) return 0;
  std::vector<double> sorted = recent_frame_ms;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  return sorted[sorted.size() / 2];
}

TimeBudget predict_next_frame(const MeasuredJob& job, double budget_ms, double elapsed_ms) {
  TimeBudget t;
  t.budget_ms = budget_ms;
  t.elapsed_ms = elapsed_ms;
  t.next_frame_ms = predict_frame_ms(job.recent_frame_ms);
  ScheduleState after = job.state;
  after.tracing_ms += t.next_frame_ms;
  after.hv_empty = false;  // the next frame may bring the first HV light: reserve for it
  const bool filtering = job.filtering && !after.all_pixels_case2;
  const bool run_next = filtering && filter_due(job.schedule, job.samples + 1, false, after);
  t.next_pass_ms = run_next ? next_run_ms(job.state) : 0.0;
  t.finish_ms = (filtering && !run_next ? next_run_ms(job.state) : 0.0) + job.display_ms;
  return t;
}

}  // namespace pxf
