#include <gtest/gtest.h>

#include "app/schedule.h"
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
