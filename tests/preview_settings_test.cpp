// Preview::set_settings keeps the accumulated samples only while they are still samples of the
// render asked for: any change of the trace parameters (sampler and replicates included) starts
// over, a change of the passes' parameters only filters again.
#include <gtest/gtest.h>

#include <functional>

#include "pathtracer/pathtracer.h"
#include "preview/preview.h"
#include "scene/load.h"
#include "tests/test_support.h"

using namespace pxf;

namespace {

int samples_after_change(const Scene& scene, const std::function<void(PreviewSettings&)>& change,
                         const std::function<void(PreviewSettings&)>& start = [](PreviewSettings&) {}) {
  PreviewSettings settings;
  start(settings);
  Preview preview(scene, settings, 16, 16);
  preview.add_frame();
  preview.add_frame();
  EXPECT_EQ(preview.samples(), 2);
  change(settings);
  preview.set_settings(settings);
  return preview.samples();
}

TEST(PreviewSettings, TraceChangesRestartAndPassChangesKeepTheSamples) {
  test_support::headless_context();
  const Scene scene = load_scene("cornell");
  EXPECT_EQ(samples_after_change(scene, [](PreviewSettings& s) { s.trace.sampler = SamplerType::Independent; }), 0);
  EXPECT_EQ(samples_after_change(scene, [](PreviewSettings& s) { s.trace.replicates = 4; }), 0);
  EXPECT_EQ(samples_after_change(scene, [](PreviewSettings& s) { s.trace.specular_sampling = true; }), 0);
  EXPECT_EQ(samples_after_change(scene, [](PreviewSettings& s) { s.trace.max_vertices = 4; }), 0);
  EXPECT_EQ(samples_after_change(scene, [](PreviewSettings& s) { s.trace.specular_chains = false; }), 0);
  // Under full specular sampling near sampling changes no sample: the accumulation stays.
  const auto full = [](PreviewSettings& s) { s.trace.specular_sampling = true; };
  EXPECT_EQ(samples_after_change(scene, [](PreviewSettings& s) { s.trace.specular_chains = false; }, full), 2);
  EXPECT_EQ(samples_after_change(scene, [](PreviewSettings& s) { s.threshold = 0.01f; }), 2);
  EXPECT_EQ(samples_after_change(scene, [](PreviewSettings& s) { s.filter.sigma_s = 4.0f; }), 2);
}

// The sigma_s of the filter's last run after `frames` frames, every frame filtered.
float sigma_after(const Scene& scene, int frames, bool shrink) {
  PreviewSettings settings;
  settings.schedule = FilterSchedule::EveryFrame;
  settings.shrink_sigma = shrink;
  Preview preview(scene, settings, 24, 16);
  for (int i = 0; i < frames; ++i) preview.add_frame(i + 1 == frames);
  EXPECT_EQ(preview.filter_params_now().sigma_s, preview.last_sigma_s());
  return preview.last_sigma_s();
}

// The preview's filter runs with sigma_s shrunk to the noise (noise_sigma_s): --sigma-s up to 4
// spp, then between 2 px and it, less as samples accumulate; --sigma-s itself when shrinking is
// off; turning it off or on filters again without restarting.
TEST(PreviewSettings, FilterSigmaShrinksToTheNoise) {
  test_support::headless_context();
  const Scene scene = load_scene("cornell");
  EXPECT_EQ(sigma_after(scene, 4, true), 8.0f);
  const float at_8 = sigma_after(scene, 8, true), at_64 = sigma_after(scene, 64, true);
  EXPECT_LT(at_8, 8.0f);
  EXPECT_LT(at_64, at_8);
  EXPECT_GE(at_64, kSigmaShrinkMin);
  EXPECT_FLOAT_EQ(sigma_after(scene, 16, false), 8.0f);
  PreviewSettings settings;
  settings.shrink_sigma = true;
  Preview preview(scene, settings, 16, 16);
  for (int i = 0; i < 16; ++i) preview.add_frame();
  const int runs = preview.filter_runs();
  settings.shrink_sigma = false;
  preview.set_settings(settings);
  EXPECT_EQ(preview.samples(), 16);
  EXPECT_EQ(preview.filter_runs(), runs + 1);
  EXPECT_EQ(preview.last_sigma_s(), 8.0f);
}

// `--time` reserves for the last frame's filter run its own work, without the range frame the
// first run rendered: the guide exists by then. After a camera change the next run renders one
// first, and the reserve grows by that frame's cost.
TEST(PreviewSettings, TimeBudgetReservesARangeFrameOnlyForANewGuide) {
  test_support::headless_context();
  const Scene scene = load_scene("cornell");
  PreviewSettings settings;  // schedule final: one measuring run, then the last frame's
  settings.motion_history = false;
  Preview preview(scene, settings, 48, 32);
  preview.add_frame(/*last_frame=*/false, /*display=*/true);
  preview.add_frame();
  ASSERT_EQ(preview.filter_runs(), 1);
  ASSERT_GT(preview.range().frames(), 0);
  ASSERT_GT(preview.range().last_ms(), 0.0);
  const double with_guide = preview.predict_next_frame(1e9, 0).finish_ms;
  Camera moved = scene.camera;
  moved.camera_to_world[3] += glm::vec4(0.01f, 0.0f, 0.0f, 0.0f);
  preview.set_camera(moved);
  ASSERT_EQ(preview.range().frames(), 0);
  EXPECT_DOUBLE_EQ(preview.predict_next_frame(1e9, 0).finish_ms - with_guide, preview.range().last_ms());
}

}  // namespace
