// The preview leaves the filter out while HV carries less than kMinHvShare of the image's energy
// (preview/preview.h): HV's noise cannot matter next to LV's there, and a run would cost time only.
#include <gtest/gtest.h>

#include "pathtracer/integrator.h"
#include "pathtracer/pathtracer.h"
#include "preview/preview.h"
#include "scene/load.h"
#include "tests/test_support.h"

using namespace pxf;

namespace {

// 4 samples per pixel: LV 1 everywhere, HV alternating between 0 and 2 hv (mean hv, variance > 0).
Accumulation accumulation_with_hv(int w, int h, float hv) {
  Accumulation acc;
  resize_accumulation(acc, w, h);
  for (int s = 0; s < 4; ++s)
    for (size_t p = 0; p < acc.samples.size(); ++p)
      accumulate_sample(acc, p, glm::vec3(1.0f), glm::vec3(s % 2 ? 2.0f * hv : 0.0f), 0, glm::vec3(0.5f));
  return acc;
}

int filter_runs_after_finish(const Scene& scene, const Accumulation& acc, int* skipped) {
  PreviewSettings settings;
  settings.schedule = FilterSchedule::PowersOfTwo;
  Preview preview(scene, settings, acc.width, acc.height);
  preview.load_accumulation(acc, 0, 4);
  preview.finish();
  *skipped = preview.filter_runs_skipped_low_hv();
  return preview.filter_runs();
}

TEST(HvShare, IsHvLuminanceOverAllLuminance) {
  EXPECT_NEAR(hv_energy_share(accumulation_with_hv(8, 8, 0.25f)), 0.25 / 1.25, 1e-6);
  EXPECT_EQ(hv_energy_share(accumulation_with_hv(8, 8, 0.0f)), 0.0);
  Accumulation black;
  resize_accumulation(black, 4, 4);
  EXPECT_EQ(hv_energy_share(black), 0.0);
}

TEST(HvShare, FilterSkippedBelowTheShareAndRunAboveIt) {
  test_support::headless_context();
  const Scene scene = load_scene("cornell");
  const int w = 24, h = 24;
  int skipped = 0;
  // HV 0.5 % of the energy: no run.
  EXPECT_EQ(filter_runs_after_finish(scene, accumulation_with_hv(w, h, 0.005f), &skipped), 0);
  EXPECT_EQ(skipped, 1);
  // HV 4.8 %: the last frame's run happens.
  EXPECT_EQ(filter_runs_after_finish(scene, accumulation_with_hv(w, h, 0.05f), &skipped), 1);
  EXPECT_EQ(skipped, 0);
}

}  // namespace
