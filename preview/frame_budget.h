// The explorer's frame budget: no display frame blocks the UI for longer than kUiBudgetMs. The
// path tracer runs on a worker thread (Preview::trace_frame), so what blocks the UI thread is the GL
// work after each traced frame: one range-buffer frame, a filter run (itself in parts: its upload,
// then the grid's GL steps, Preview::begin_filter_run), the blend and tone map
// (Preview::queue_passes), and, with the reprojected history, each camera change (the view kept,
// then a range-buffer frame and the reprojection as two more steps: Preview::begin_camera_change).
// These steps are spread over display frames: each display frame runs the queued steps whose
// predicted costs (a camera change's: the last one's), added to the UI's own work (the drawing of
// the views and the window, the longest of the last 8 frames'), still fit the budget. A pure
// function of the predicted costs, so it is tested with a fake clock (preview/frame_budget_test.cpp).
#pragma once
#include <vector>

namespace pxf {

// Longest time one display frame may keep the UI thread busy.
constexpr double kUiBudgetMs = 100.0;

// The GL steps that follow a traced frame, in the order they run, and those that follow a camera
// change with the reprojected history (Preview::begin_camera_change) before the new view's first
// traced frame.
enum class PassStep {
  RangeFrame,  // one antialiasing frame of the range buffer, if the pass budget allows
  Filter,      // a filter run, if the schedule makes one due: one part per step (stays queued until done)
  Display,     // upload, blend and tone map
  ViewRange,   // the new view's first range-buffer frame (its distances, for the reprojection)
  Reproject,   // the kept view reprojected into the new one, and the first frame's path counts
};

// Whether the next queued step (predicted to take next_ms) runs in this display frame, which has
// already spent used_ms on UI work, on waiting for the tracer and on earlier steps: it must fit in
// budget_ms. `fresh`: nothing but the frame's UI work ran yet (no wait, no step); then the step
// always runs, so that the queue drains. A step that does not fit even alone is so deferred to a
// display frame of its own (the explorer shows the longest display frame; the default filter at
// 512x512 fits, the exact bilateral filter does not).
bool step_fits_display_frame(double used_ms, bool fresh, double next_ms, double budget_ms = kUiBudgetMs);

}  // namespace pxf
