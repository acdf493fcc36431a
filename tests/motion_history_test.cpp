// The reprojected history of a moving camera (docs/method.md 4.1) in the preview core:
// once the camera rests, the history's weight falls to 0 and the render converges to the one that
// never moved; while it moves, the history stands beside the fresh samples.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "scene/camera_controls.h"
#include "app/render_output.h"
#include "gl/grid_filter.h"
#include "image/metrics.h"
#include "pathtracer/accumulation_state.h"
#include "preview/preview.h"
#include "scene/load.h"
#include "tests/test_support.h"

using namespace pxf;

namespace {

constexpr int kSize = 32;

Camera orbited(const Scene& scene, float dx) {
  CameraController control(scene.camera, scene_bounds(scene));
  control.orbit(dx, 0.0f);
  return control.camera();
}

std::vector<Layer> render_at(Preview& preview, int spp) {
  for (int i = 0; i < spp; ++i) preview.add_frame(i + 1 == spp, false);
  return preview.buffers();
}

// 64 frames after a move against 64 spp of a camera that never moved: the same fresh samples (the
// first frame after the move traced more paths where the history held few, so the path tracer
// alone, given the same counts, is the reference for those), and a final image within the
// tolerance of the consistency test's last checkpoint (the filtered image 4 % NRMSE from the
// unfiltered one there; here both filter nearly the same samples).
TEST(MotionHistory, AfterTheCameraRestsTheRenderConvergesToTheStaticOne) {
  test_support::headless_context();
  Scene scene = load_scene("cornell");
  PreviewSettings settings;
  Preview still(scene, settings, kSize, kSize);
  still.converge_range_buffer();
  const std::vector<Layer> reference = render_at(still, 64);

  Preview moved(scene, settings, kSize, kSize);
  moved.set_camera(orbited(scene, 40.0f));
  render_at(moved, 4);
  moved.set_camera(scene.camera);
  ASSERT_TRUE(moved.history() && moved.history()->reprojected());
  moved.add_frame(false, false);
  EXPECT_TRUE(moved.history_active());
  const std::vector<uint32_t> first_frame = moved.pixel_samples();
  moved.converge_range_buffer();
  const std::vector<Layer> after = render_at(moved, 63);
  EXPECT_FALSE(moved.history_active());

  ProgressiveRenderer same_paths(scene, settings.trace, kSize, kSize);
  same_paths.add_frame(std::vector<uint8_t>(first_frame.begin(), first_frame.end()));
  for (int i = 0; i < 63; ++i) same_paths.add_frame();
  EXPECT_EQ(layer_image(after, "lv").pixels, same_paths.lv_image().pixels);
  EXPECT_EQ(layer_image(after, "hv").pixels, same_paths.hv_image().pixels);
  // The passes read the fresh samples again, exactly.
  EXPECT_EQ(moved.inputs().hv_image().pixels, same_paths.hv_image().pixels);
  // And filter and blend them as a render of those samples that never moved does.
  AccumulationState state;
  state.frames = {{0, 64}};
  state.acc = same_paths.accumulation();
  state.traced = same_paths.pixel_frames();
  Preview unmoved(scene, settings, kSize, kSize);
  unmoved.converge_range_buffer();
  unmoved.load_state(state);
  unmoved.finish();
  const double nrmse = compare_images(layer_image(after, "final"), unmoved.final_image()).nrmse_percent;
  EXPECT_LT(nrmse, 1.0);
  // The extra paths of the first frame changed few pixels: still close to the static render.
  EXPECT_LT(compare_images(layer_image(after, "final"), layer_image(reference, "final")).nrmse_percent, 4.0);
}

// A preview of cornell after 16 frames, moved by an orbit of `dx` pixels (its first frame not yet
// traced), and the extra paths its reprojected history asks for in all.
struct MovedPreview {
  Scene scene = load_scene("cornell");
  Preview preview{scene, PreviewSettings{}, kSize, kSize};
  Image history;  // the reprojected history: alpha the samples it holds
  uint64_t wanted_extra = 0;
  explicit MovedPreview(float dx) {
    render_at(preview, 16);
    preview.set_camera(orbited(scene, dx));
    history = preview.history()->history_lv_image();
    for (size_t p = 0; p < history.pixels.size() / 4; ++p) wanted_extra += shared::first_frame_paths(held(p)) - 1;
  }
  float held(size_t p) const { return history.pixels[4 * p + 3]; }
};

// A move that uncovers most of the image asks for more extra paths than kFirstFrameExtraShare of a
// uniform frame: each pixel's extra paths are scaled down alike, and the frame stays within the bound.
TEST(MotionHistory, TheFirstFramesExtraPathsAreBoundedOnALargeMove) {
  test_support::headless_context();
  MovedPreview moved(300.0f);
  Preview& preview = moved.preview;
  const double bound = kFirstFrameExtraShare * kSize * kSize;
  ASSERT_GT(static_cast<double>(moved.wanted_extra), bound);  // the case under test
  preview.add_frame(false, true);
  uint64_t extra = 0;
  for (size_t p = 0; p < preview.pixel_samples().size(); ++p) {
    const uint32_t n = preview.pixel_samples()[p];
    ASSERT_GE(n, 1u);
    const int asked = shared::first_frame_paths(moved.held(p)) - 1;
    const int scaled = static_cast<int>(std::floor(asked * bound / static_cast<double>(moved.wanted_extra)));
    EXPECT_EQ(n, 1u + scaled) << p;
    extra += n - 1;
  }
  EXPECT_LE(static_cast<double>(extra), bound);
}

TEST(MotionHistory, FirstFramePathsFillTheHistoryUpToFourSamples) {
  using shared::first_frame_paths;
  EXPECT_EQ(first_frame_paths(0.0f), 4);
  EXPECT_EQ(first_frame_paths(0.5f), 4);
  EXPECT_EQ(first_frame_paths(2.5f), 2);
  EXPECT_EQ(first_frame_paths(3.0f), 1);
  EXPECT_EQ(first_frame_paths(8.0f), 1);
  EXPECT_EQ(first_frame_paths(-1.0f), 4);
  EXPECT_EQ(first_frame_paths(std::numeric_limits<float>::quiet_NaN()), 4);
  EXPECT_EQ(first_frame_paths(std::numeric_limits<float>::infinity()), 4);  // clean(): not a count
}

// The first frame after a move traces shared::first_frame_paths(history count) paths per pixel:
// more where the history holds fewer than kHistoryFirstFrameSamples samples (the pixels the move
// uncovered, those outside the previous view), one where it holds enough.
TEST(MotionHistory, PixelsWithoutHistoryTraceMorePathsInTheFirstFrame) {
  test_support::headless_context();
  MovedPreview moved(6.0f);
  Preview& preview = moved.preview;
  const Image outcome = preview.history()->outcome_image();
  ASSERT_LE(static_cast<double>(moved.wanted_extra), kFirstFrameExtraShare * kSize * kSize);  // not scaled down
  preview.add_frame(false, true);
  const std::vector<uint32_t>& paths = preview.pixel_samples();
  int more = 0, one = 0;
  for (size_t p = 0; p < paths.size(); ++p) {
    const float held = moved.held(p);
    ASSERT_EQ(paths[p], static_cast<uint32_t>(shared::first_frame_paths(held))) << p;
    if (outcome.pixels[p] != shared::kHistoryKept) {
      EXPECT_EQ(paths[p], shared::kHistoryFirstFrameSamples) << p;
    }
    more += paths[p] > 1;
    one += held >= shared::kHistoryFirstFrameSamples && paths[p] == 1;
  }
  EXPECT_GT(more, 0);
  EXPECT_GT(one, kSize * kSize / 2);
  // In that frame the pixels without history pass their variance unknown (var_image: 0), as a
  // one-path pixel does (Preview::hide_first_frame_variances).
  const Image first_variance = preview.inputs().var_image();
  for (size_t p = 0; p < paths.size(); ++p) {
    if (outcome.pixels[p] != shared::kHistoryKept) {
      ASSERT_EQ(first_variance.pixels[p], 0.0f) << p;
    }
  }
  // The next frame is uniform again, and their variance is known.
  preview.add_frame(false, true);
  for (size_t p = 0; p < paths.size(); ++p)
    EXPECT_EQ(preview.pixel_samples()[p], static_cast<uint32_t>(shared::first_frame_paths(moved.held(p))) + 1);
  const Image second_variance = preview.inputs().var_image();
  int known = 0;
  for (size_t p = 0; p < paths.size(); ++p) known += outcome.pixels[p] != shared::kHistoryKept && second_variance.pixels[p] > 0.0f;
  EXPECT_GT(known, 0);
}

// One frame after a small orbit, the history counts: most pixels reprojected, their weight high,
// and the final image closer to a converged render than the one frame alone.
TEST(MotionHistory, ASmallMoveKeepsMostOfTheImage) {
  test_support::headless_context();
  Scene scene = load_scene("cornell");
  PreviewSettings settings;
  Preview preview(scene, settings, kSize, kSize);
  render_at(preview, 16);
  const Camera now = orbited(scene, 6.0f);
  preview.set_camera(now);
  preview.add_frame(false, true);
  ASSERT_TRUE(preview.history_active());
  const Image outcome = preview.history()->outcome_image();
  int kept = 0;
  for (float o : outcome.pixels) kept += o == shared::kHistoryKept;
  EXPECT_GT(kept, kSize * kSize * 3 / 4);
  const Image weight = preview.history()->weight_image();
  double mean_weight = 0;
  for (float w : weight.pixels) mean_weight += w / weight.pixels.size();
  EXPECT_GT(mean_weight, 0.6);

  Preview reference(scene, settings, kSize, kSize);
  reference.set_camera(now);
  const std::vector<Layer> converged = render_at(reference, 256);
  Preview restart(scene, settings, kSize, kSize);
  restart.set_camera(now);
  const std::vector<Layer> one = render_at(restart, 1);
  const Image target = unfiltered_image(converged);
  // On display values, as pxf bench motion measures: the HDR NRMSE is the fireflies' of the
  // pixels that take no history (the glass and mirror spheres, silhouettes) in both.
  const double with_history = compare_display(preview.final_image(), target).display_nrmse_percent;
  const double restarted = compare_display(unfiltered_image(one), target).display_nrmse_percent;
  std::printf("1 spp after a move: display NRMSE %.1f %% with the history, %.1f %% restarted\n", with_history,
              restarted);
  EXPECT_LT(with_history, 0.5 * restarted);
}

}  // namespace

// The explorer runs a filter run in steps, one queued Filter step per call (the grid's four GL
// steps after the run's upload), so that its frame budget can spread them. Between two of them the
// views show the last whole run's L_f, and a camera change abandons the run: what follows is
// exactly what follows a change after the whole run.
TEST(MotionHistory, AFilterRunAbandonedBetweenItsStepsByACameraChangeChangesNothing) {
  test_support::headless_context();
  Scene scene = load_scene("cornell");
  PreviewSettings settings;
  settings.schedule = FilterSchedule::EveryFrame;
  const Camera moved_to = orbited(scene, 30.0f);
  std::vector<Layer> results[2];
  for (const bool abandon : {false, true}) {
    Preview preview(scene, settings, kSize, kSize);
    const std::vector<Layer> before = render_at(preview, 4);
    preview.trace_frame();
    preview.queue_passes(false, true);
    std::vector<PassStep> steps;
    while (preview.passes_pending() && !(abandon && steps.size() == 3)) {
      steps.push_back(preview.next_pass());
      EXPECT_GE(preview.predict_pass_ms(steps.back()), 0.0);
      preview.run_next_pass();
    }
    if (abandon) {
      ASSERT_TRUE(preview.passes_pending());
      EXPECT_EQ(preview.next_pass(), PassStep::Filter) << "the run is open: its grid steps are still queued";
      // The views drawn between two steps show the last whole run's L_f.
      EXPECT_EQ(layer_image(preview.buffers(), "hv_filtered").pixels, layer_image(before, "hv_filtered").pixels);
    } else {
      // RangeFrame (when its budget allows), the run's upload and its four grid steps, Display.
      EXPECT_EQ(std::count(steps.begin(), steps.end(), PassStep::Filter), 1 + GridFilter::kSteps);
      EXPECT_EQ(steps.back(), PassStep::Display);
    }
    preview.begin_camera_change(moved_to);
    while (preview.passes_pending()) preview.run_next_pass();
    results[abandon] = render_at(preview, 3);
  }
  for (const char* layer : {"final", "hv_filtered", "var_f"})
    EXPECT_EQ(layer_image(results[0], layer).pixels, layer_image(results[1], layer).pixels) << layer;
}

// A camera change resets the samples and their case counts, but the image and the views still show
// the last blend until the new view's first display: the counts the explorer's status line and
// case legend show are that blend's (they read 0 % everywhere while moving before).
TEST(MotionHistory, TheShownCaseCountsStayTheShownBlendsAfterAMove) {
  test_support::headless_context();
  Scene scene = load_scene("cornell");
  PreviewSettings settings;
  Preview preview(scene, settings, kSize, kSize);
  const std::vector<Layer> shown = render_at(preview, 4);
  std::array<uint32_t, kBlendCaseCount> from_image{};
  for (float code : layer_image(shown, "case").pixels) ++from_image[static_cast<int>(code)];
  ASSERT_EQ(preview.shown_case_counts(), from_image);
  const Image display = preview.display_image();

  preview.begin_camera_change(orbited(scene, 30.0f));
  EXPECT_EQ(preview.case_counts(), (std::array<uint32_t, kBlendCaseCount>{}));
  EXPECT_EQ(preview.display_image().pixels, display.pixels) << "the shown image is still the last blend's";
  EXPECT_EQ(preview.shown_case_counts(), from_image);
  while (preview.passes_pending()) preview.run_next_pass();
  preview.add_frame(false, true);
  EXPECT_EQ(preview.shown_case_counts(), preview.case_counts()) << "the new view's first display";
}
