// The explorer's frame budget under a fake clock: a simulated display loop runs queued GL steps
// with known costs; no display frame may exceed kUiBudgetMs unless one step alone does, and the
// queue always drains.
#include "preview/frame_budget.h"

#include <gtest/gtest.h>

#include <deque>
#include <vector>

namespace pxf {
namespace {

struct DisplayFrames {
  std::vector<double> busy_ms;   // per display frame: UI work + GL steps run in it
  std::vector<int> steps;        // steps run per display frame
};

// The explorer's loop (app/explorer/explorer.cpp run_passes) with fake costs: each display frame spends
// ui_ms on its own work, then runs queued steps while step_fits_display_frame allows. The
// prediction of a step is its true cost (the explorer predicts from the newest measurement).
DisplayFrames simulate(std::deque<double> queue, double ui_ms) {
  DisplayFrames out;
  while (!queue.empty()) {
    double used = ui_ms;
    int steps = 0;
    while (!queue.empty() && step_fits_display_frame(used, steps == 0, queue.front())) {
      used += queue.front();  // the fake clock advances by the step's cost
      queue.pop_front();
      ++steps;
    }
    out.busy_ms.push_back(used);
    out.steps.push_back(steps);
    if (out.busy_ms.size() > 100) break;  // guards the test against a queue that never drains
  }
  return out;
}

TEST(FrameBudget, StepsThatFitAreSpreadSoNoDisplayFrameExceedsTheBudget) {
  // Range frame 30 ms, filter 60 ms, display 40 ms after 8 ms of UI: 138 ms in one frame would
  // block; spread: [range, filter] = 98 ms, then [display] = 48 ms.
  const DisplayFrames f = simulate({30, 60, 40}, 8);
  ASSERT_EQ(f.busy_ms.size(), 2u);
  EXPECT_EQ(f.steps[0], 2);
  EXPECT_EQ(f.steps[1], 1);
  for (double ms : f.busy_ms) EXPECT_LE(ms, kUiBudgetMs);
}

TEST(FrameBudget, CheapStepsRunInOneDisplayFrame) {
  const DisplayFrames f = simulate({5, 20, 10}, 8);
  ASSERT_EQ(f.busy_ms.size(), 1u);
  EXPECT_DOUBLE_EQ(f.busy_ms[0], 43);
}

TEST(FrameBudget, AStepOverTheBudgetRunsAloneAndTheQueueDrains) {
  // A 1700 ms exact bilateral filter run cannot be split: it gets a display frame of its own,
  // and the steps around it are not delayed into it.
  const DisplayFrames f = simulate({30, 1700, 40}, 8);
  ASSERT_EQ(f.busy_ms.size(), 3u);
  EXPECT_EQ(f.steps, (std::vector<int>{1, 1, 1}));
  EXPECT_DOUBLE_EQ(f.busy_ms[1], 1708);
  EXPECT_LE(f.busy_ms[0], kUiBudgetMs);
  EXPECT_LE(f.busy_ms[2], kUiBudgetMs);
}

TEST(FrameBudget, ExactFitAndZeroCostSteps) {
  EXPECT_TRUE(step_fits_display_frame(60, false, 40));  // exactly the budget
  EXPECT_FALSE(step_fits_display_frame(60, false, 40.001));
  EXPECT_TRUE(step_fits_display_frame(8, true, 400));     // nothing ran yet in this frame: always
  EXPECT_FALSE(step_fits_display_frame(38, false, 80));   // after a 30 ms wait for the tracer: next frame
  EXPECT_TRUE(step_fits_display_frame(100, false, 0));    // a step that will do nothing
  EXPECT_FALSE(step_fits_display_frame(10, false, 50, 40));  // another budget
}

}  // namespace
}  // namespace pxf
