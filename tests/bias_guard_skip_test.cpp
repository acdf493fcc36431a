// The preview leaves the bias guard's passes out once a filter run skipped every pixel (preview/preview.cpp,
// blend_and_tonemap): every pixel is then case 2, where the guard changes nothing.
#include <gtest/gtest.h>

#include "gl/blend_pass.h"
#include "pathtracer/integrator.h"
#include "pathtracer/pathtracer.h"
#include "preview/preview.h"
#include "scene/load.h"
#include "tests/test_support.h"

using namespace pxf;

namespace {

// 4 samples per pixel: LV 1, HV hv (1 - spread) and hv (1 + spread) in turn.
Accumulation accumulation_with(int w, int h, float hv, float spread) {
  Accumulation acc;
  resize_accumulation(acc, w, h);
  for (int s = 0; s < 4; ++s)
    for (size_t p = 0; p < acc.samples.size(); ++p)
      accumulate_sample(acc, p, glm::vec3(1.0f), glm::vec3(hv * (s % 2 ? 1.0f + spread : 1.0f - spread)), 0,
                        glm::vec3(0.5f));
  return acc;
}

TEST(BiasGuardSkip, LeftOutOnceEveryPixelIsCase2WithTheSameImage) {
  test_support::headless_context();
  const Scene scene = load_scene("cornell");
  const int w = 24, h = 24;
  PreviewSettings settings;
  settings.schedule = FilterSchedule::PowersOfTwo;
  ASSERT_TRUE(settings.bias_guard);
  // HV nearly constant per pixel: u far below t everywhere, the last run skips every pixel.
  Preview quiet(scene, settings, w, h);
  quiet.load_accumulation(accumulation_with(w, h, 0.5f, 1e-3f), 0, 4);
  quiet.finish();
  ASSERT_TRUE(quiet.filter_stopped());
  EXPECT_EQ(quiet.blend().guard_runs(), 0);
  // The same blend with the guard's passes gives the same image.
  BlendPass guarded(w, h);
  guarded.run(quiet.inputs(), &quiet.filtered_output(), &quiet.range().guide(), quiet.threshold_now(),
              BlendParams{range_weights(settings.filter), true}, quiet.filter().centre_weight(),
              &quiet.range().surface());
  EXPECT_EQ(guarded.guard_runs(), 1);
  EXPECT_EQ(guarded.final_image().pixels, quiet.final_image().pixels);
  EXPECT_EQ(guarded.case_counts()[kCaseUnfiltered], uint32_t(w * h));
  // Noisy HV: the filter is used, and so is the guard.
  Preview noisy(scene, settings, w, h);
  noisy.load_accumulation(accumulation_with(w, h, 0.5f, 1.0f), 0, 4);
  noisy.finish();
  ASSERT_FALSE(noisy.filter_stopped());
  EXPECT_GT(noisy.blend().guard_runs(), 0);
}

}  // namespace
