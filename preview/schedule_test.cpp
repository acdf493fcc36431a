#include <gtest/gtest.h>

#include "preview/schedule.h"

#include <algorithm>
#include "image/image.h"

using namespace pxf;

TEST(FilterSchedule, RunsOnPowersOfTwoAndTheLastFrame) {
  ScheduleState s;
  s.hv_empty = false;
  std::vector<int> runs;
  for (int n = 1; n <= 40; ++n)
    if (filter_due(FilterSchedule::PowersOfTwo, n, n == 40, s)) runs.push_back(n);
  EXPECT_EQ(runs, (std::vector<int>{1, 2, 4, 8, 16, 32, 40}));
}

TEST(FilterSchedule, EveryFrameRunsEachFrame) {
  ScheduleState s;
  s.hv_empty = false;
  for (int n = 1; n <= 9; ++n) EXPECT_TRUE(filter_due(FilterSchedule::EveryFrame, n, false, s));
}

TEST(FilterSchedule, SkipsWhenNothingNeedsFiltering) {
  ScheduleState empty;  // HV empty: a scene lit only directly
  EXPECT_FALSE(filter_due(FilterSchedule::EveryFrame, 4, true, empty));
  ScheduleState converged;
  converged.hv_empty = false;
  converged.all_pixels_case2 = true;
  EXPECT_FALSE(filter_due(FilterSchedule::PowersOfTwo, 64, true, converged));
  ScheduleState s;
  s.hv_empty = false;
  EXPECT_FALSE(filter_due(FilterSchedule::PowersOfTwo, 0, false, s));
}

TEST(FilterSchedule, NamesRoundTrip) {
  for (const auto& name : filter_schedule_names()) EXPECT_NO_THROW(parse_filter_schedule(name));
  EXPECT_THROW(parse_filter_schedule("sometimes"), Error);
}

namespace {

// A fake clock: every frame traces `frame_ms`, every filter run (range included) costs `run_ms`.
struct FakeRun {
  std::vector<int> runs;         // sample counts at which the filter ran
  bool share_held = true;        // passes <= kPassShare x tracing at every frame after the first run
  double worst_share_after_first = 0;
};

FakeRun simulate_schedule(FilterSchedule schedule, double frame_ms, double run_ms, int frames) {
  FakeRun r;
  ScheduleState s;
  s.hv_empty = false;
  for (int n = 1; n <= frames; ++n) {
    s.tracing_ms += frame_ms;
    if (filter_due(schedule, n, n == frames, s)) {
      s.last_run_ms = run_ms;
      s.pass_ms += run_ms;
      r.runs.push_back(n);
    }
    // The first run measures the cost and the last frame's run is the one the user waits for;
    // every other moment is bounded.
    if (r.runs.size() > 1 && n < frames) {
      const double share = s.pass_ms / s.tracing_ms;
      r.worst_share_after_first = std::max(r.worst_share_after_first, share);
      if (share > kPassShare + 1e-12) r.share_held = false;
    }
  }
  return r;
}

FakeRun simulate_budget_schedule(double frame_ms, double run_ms, int frames) {
  return simulate_schedule(FilterSchedule::Budget, frame_ms, run_ms, frames);
}

bool is_pow2(int n) { return n > 0 && (n & (n - 1)) == 0; }

}  // namespace

TEST(FilterSchedule, BudgetBoundsTheShareOfFilterAndRangeForEveryCost) {
  for (double run_ms : {0.5, 5.0, 50.0, 100.0, 1000.0, 2000.0, 20000.0}) {
    const FakeRun r = simulate_budget_schedule(/*frame_ms=*/90.0, run_ms, /*frames=*/4096);
    EXPECT_TRUE(r.share_held) << "run " << run_ms << " ms: share " << r.worst_share_after_first;
    ASSERT_FALSE(r.runs.empty());
    EXPECT_EQ(r.runs.front(), 1) << "the first power of two measures the cost";
    EXPECT_EQ(r.runs.back(), 4096) << "the last frame filters";
    for (size_t i = 0; i + 1 < r.runs.size(); ++i) EXPECT_TRUE(is_pow2(r.runs[i])) << "never off the pow2 grid";
  }
  // Expensive runs are spaced out: after the 2000 ms measuring run at 1 spp, the second run needs
  // 4000 ms <= 10 % of the tracing, i.e. >= 445 frames of 90 ms: the next power of two is 512.
  const FakeRun costly = simulate_budget_schedule(90.0, 2000.0, 4096);
  EXPECT_EQ(costly.runs, (std::vector<int>{1, 512, 1024, 2048, 4096}));
}

TEST(FilterSchedule, BudgetIsPowersOfTwoWhenPassesAreFree) {
  const FakeRun r = simulate_budget_schedule(90.0, 0.0, 40);
  EXPECT_EQ(r.runs, (std::vector<int>{1, 2, 4, 8, 16, 32, 40}));
}

// A headless job shows its last frame only: one run to measure the cost (which --time reserves
// for the last frame), then the last frame's, whatever a run costs; and only the last frame's once
// a cost is known (after a camera change, say).
TEST(FilterSchedule, FinalRunsToMeasureThenOnTheLastFrameOnly) {
  for (double run_ms : {0.5, 5.0, 2000.0}) {
    const FakeRun r = simulate_schedule(FilterSchedule::Final, 90.0, run_ms, 300);
    EXPECT_EQ(r.runs, (std::vector<int>{1, 300})) << run_ms;
  }
  ScheduleState measured;
  measured.hv_empty = false;
  measured.last_run_ms = 30;
  for (int n = 1; n < 64; ++n) EXPECT_FALSE(filter_due(FilterSchedule::Final, n, false, measured)) << n;
  EXPECT_TRUE(filter_due(FilterSchedule::Final, 64, true, measured));
}

TEST(FilterSchedule, BudgetStillFiltersTheLastFrame) {
  ScheduleState s;
  s.hv_empty = false;
  s.tracing_ms = 100;
  s.pass_ms = 5000;
  s.last_run_ms = 5000;  // far over the share
  EXPECT_FALSE(filter_due(FilterSchedule::Budget, 64, false, s));
  EXPECT_TRUE(filter_due(FilterSchedule::Budget, 64, true, s));
}

TEST(TimeBudget, PredictsTheMedianFrame) {
  EXPECT_EQ(predict_frame_ms({}), 0.0);
  EXPECT_EQ(predict_frame_ms({90, 3000, 95, 91, 92}), 92.0);  // one slow frame does not count
}

namespace {

struct FakeJob {
  int samples = 0;
  double end_ms = 0;      // fake clock at the end of the finish
  double overrun_ms = 0;  // what one more frame would have ended at
};

// The render loop of `pxf render --time` against a fake clock: a setup, frames of `frame_ms`,
// filter runs of `run_ms` on the schedule, a finish of the last run (if not done) plus `display_ms`.
FakeJob simulate_timed_job(FilterSchedule schedule, bool filtering, double budget_ms, double setup_ms,
                           double frame_ms, double run_ms, double display_ms) {
  MeasuredJob job;
  job.schedule = schedule;
  job.filtering = filtering;
  job.state.hv_empty = false;
  double clock = setup_ms;
  int filtered_at = -1;
  for (int i = 0;; ++i) {
    const TimeBudget t = predict_next_frame(job, budget_ms, clock);
    if (i > 0 && !next_frame_fits(t)) break;
    clock += frame_ms;
    ++job.samples;
    job.state.tracing_ms += frame_ms;
    job.recent_frame_ms.push_back(frame_ms);
    if (filtering && filter_due(schedule, job.samples, false, job.state)) {
      clock += run_ms;
      job.state.pass_ms += run_ms;
      job.state.last_run_ms = run_ms;
      filtered_at = job.samples;
    }
    if (i == 0) {
      clock += display_ms;  // the first frame is displayed: that measures the display
      job.display_ms = display_ms;
    }
  }
  FakeJob r;
  r.samples = job.samples;
  const double finish = (filtering && filtered_at != job.samples ? run_ms : 0.0) + display_ms;
  r.end_ms = clock + finish;
  // One more frame ends after exactly one more filter run (its scheduled one or the finish's).
  r.overrun_ms = clock + frame_ms + (filtering ? run_ms : 0.0) + display_ms;
  return r;
}

}  // namespace

TEST(TimeBudget, StopsSoThatTheFinishEndsWithinTheBudget) {
  for (FilterSchedule schedule : {FilterSchedule::Budget, FilterSchedule::PowersOfTwo, FilterSchedule::EveryFrame})
    for (bool filtering : {true, false})
      for (double budget : {3000.0, 10000.0, 60000.0})
        for (double run_ms : {10.0, 500.0, 1500.0}) {
          const FakeJob j = simulate_timed_job(schedule, filtering, budget, 400.0, 90.0, run_ms, 40.0);
          SCOPED_TRACE(testing::Message() << "schedule " << static_cast<int>(schedule) << " filtering " << filtering
                                          << " budget " << budget << " run " << run_ms);
          EXPECT_GE(j.samples, 1);
          EXPECT_LE(j.end_ms, budget);
          // Tight: one more frame (with its finish) would not have fit.
          EXPECT_GT(j.overrun_ms, budget);
        }
}

// The next run renders a range frame first only while the guide has none (the first run, a new
// camera): the finish of a job whose guide exists reserves the run's own work and the display, and
// the budget schedule's share counts the range frame only where it is due.
TEST(TimeBudget, ReservesTheRangeFrameOnlyWhileTheGuideHasNone) {
  MeasuredJob job;
  job.schedule = FilterSchedule::Final;
  job.state.hv_empty = false;
  job.samples = 5;
  job.state.tracing_ms = 50;
  job.recent_frame_ms = {10};
  job.state.last_run_ms = 30;
  job.display_ms = 5;
  EXPECT_DOUBLE_EQ(predict_next_frame(job, 1000, 0).finish_ms, 35.0);
  job.state.first_range_ms = 20;
  EXPECT_DOUBLE_EQ(predict_next_frame(job, 1000, 0).finish_ms, 55.0);
  ScheduleState s;
  s.hv_empty = false;
  s.tracing_ms = 1000;
  s.pass_ms = 40;
  s.last_run_ms = 50;  // 40 + 50 within 10 % of 1000
  EXPECT_TRUE(filter_due(FilterSchedule::Budget, 64, false, s));
  s.first_range_ms = 20;  // 40 + 50 + 20 is not
  EXPECT_FALSE(filter_due(FilterSchedule::Budget, 64, false, s));
}

TEST(TimeBudget, NoBudgetNeverStops) {
  TimeBudget t;
  t.elapsed_ms = 1e12;
  t.next_frame_ms = 1e9;
  EXPECT_TRUE(next_frame_fits(t));
}

// While a reprojected history has weight (a moving camera, docs/method.md 4.1) the filter runs on
// every frame, also where the budget would leave it out; once the history is gone, the budget again.
TEST(FilterSchedule, RunsEveryFrameWhileTheHistoryHasWeight) {
  ScheduleState state;
  state.hv_empty = false;
  state.last_run_ms = 50;  // far beyond 10 % of the tracing so far
  state.tracing_ms = 100;
  for (int samples : {1, 3, 5})
    EXPECT_FALSE(filter_due(FilterSchedule::Budget, samples, false, state)) << samples;
  state.history_active = true;
  for (int samples : {1, 3, 5})
    EXPECT_TRUE(filter_due(FilterSchedule::Budget, samples, false, state)) << samples;
  state.all_pixels_case2 = true;  // nothing to filter: not even with a history
  EXPECT_FALSE(filter_due(FilterSchedule::Budget, 3, false, state));
}
