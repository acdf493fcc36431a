// When the (expensive) cross bilateral filter runs. The blend and tone map run every displayed
// frame with the newest L_f; the filter only on this schedule. Also the `--time` stopping rule.
// Both decisions are pure functions of measured times passed in, so they are tested with a fake
// clock.
#pragma once
#include <string>
#include <vector>

namespace pxf {

// pow2: at power-of-two sample counts. every: each frame. budget (the explorer's): at power-of-two
// sample counts, but only while filter + range stay within kPassShare of the tracing time.
// final (the default of headless jobs: they show only their last frame): once at the first frame
// with HV light, which measures a run's cost for the --time reserve, then on the last frame.
enum class FilterSchedule { PowersOfTwo, EveryFrame, Budget, Final };
const std::vector<std::string>& filter_schedule_names();  // "pow2", "every", "budget", "final"
FilterSchedule parse_filter_schedule(const std::string& name);

// The budget schedule's bound: filter + range time at most this share of the path-tracing time.
constexpr double kPassShare = 0.10;

struct ScheduleState {
  bool hv_empty = true;          // no HV radiance yet anywhere (e.g. a scene lit only directly)
  bool all_pixels_case2 = false; // every pixel already meets the threshold unfiltered
  bool have_filtered = false;    // an L_f exists from an earlier run
  // A reprojected history still has weight (a moving camera, docs/method.md 4.1): the filter runs
  // on every frame, as the history makes a few fresh samples worth filtering.
  bool history_active = false;
  // Measured since the last reset (ms), for the budget schedule.
  double tracing_ms = 0;   // path tracing
  double pass_ms = 0;      // filter + range runs
  double last_run_ms = 0;  // the newest filter run's own work, its range frame apart; 0 = none measured yet
  // The range frame the next run renders first: the newest range frame's cost while the guide has
  // none (the first run, a new camera), 0 once it has one. The last run of a job with a guide needs
  // none: counting the first run's range frame in its prediction kept a 1 s job's last 4 % idle.
  double first_range_ms = 0;
};

// The predicted cost of the next filter run: its own work and, where the guide has none yet, the
// range frame it renders first.
inline double next_run_ms(const ScheduleState& s) { return s.last_run_ms + s.first_range_ms; }

// Whether the filter runs after the frame that brought the sample count to `samples`.
// Budget: a run is due at a power of two when the passes so far plus the predicted run (the newest
// run's cost) fit in kPassShare of the tracing so far. The first run (nothing measured yet) comes
// at the first power of two: it is what measures the cost. Final: that first run only. The last
// frame always filters.
bool filter_due(FilterSchedule schedule, int samples, bool last_frame, const ScheduleState& state);

// `--time`: a wall-clock budget for a whole job. Times in ms from the start of the job.
struct TimeBudget {
  double budget_ms = 0;      // <= 0: no budget
  double elapsed_ms = 0;     // now
  double next_frame_ms = 0;  // predicted cost of the next frame (tracing + upload)
  double next_pass_ms = 0;   // predicted cost of the passes due after the next frame (0 if none)
  double finish_ms = 0;      // predicted cost of finishing after it (last filter run, blend, tone map)
};

// Whether one more frame, with the passes it triggers and the finish after it, fits in the budget.
bool next_frame_fits(const TimeBudget& t);

// What a job has measured so far, for predicting one more frame.
struct MeasuredJob {
  FilterSchedule schedule = FilterSchedule::Budget;
  bool filtering = true;                 // filter enabled
  int samples = 0;                       // frames traced so far
  ScheduleState state;                   // tracing and pass times so far, newest run's cost
  std::vector<double> recent_frame_ms;   // tracing time of the last frames
  double display_ms = 0;                 // upload + blend + tone map, measured once
};

// The prediction for one more frame: its tracing (median of the recent frames), the filter run it
// makes due, and the finish after it (the last frame's run unless that frame's scheduled run
// already is it, then the display).
TimeBudget predict_next_frame(const MeasuredJob& job, double budget_ms, double elapsed_ms);

// The prediction of the next frame's cost from the measured costs of the recent frames: their
// median (robust to one slow frame on a shared machine). 0 when nothing was measured.
double predict_frame_ms(const std::vector<double>& recent_frame_ms);

}  // namespace pxf
