// The --time first-frame check (app/first_frame.h): the probe's size, the scaling to the image's
// pixels and the refusal, as pure functions of measured times (no wall time is asserted).
#include "app/first_frame.h"

#include <gtest/gtest.h>

namespace pxf {
namespace {

TEST(FirstFrame, ProbeKeepsTheAspectAtAboutTheProbePixels) {
  int w = 0, h = 0;
  probe_size(4000, 4000, w, h);
  EXPECT_EQ(w, 256);
  EXPECT_EQ(h, 256);
  probe_size(16384, 100, w, h);
  EXPECT_NEAR(double(w) / h, 163.84, 10.0);
  EXPECT_NEAR(double(w) * h, kProbePixels, 0.05 * kProbePixels);
  probe_size(100000, 1, w, h);  // never below one pixel a side
  EXPECT_GE(h, 1);
}

TEST(FirstFrame, CostScalesWithThePixels) {
  // 4000x4000 is 244x the probe: a 125 ms probe frame predicts about 30.5 s.
  EXPECT_NEAR(scaled_first_frame_ms(125.0, kProbePixels, 4000.0 * 4000.0), 30518.0, 1.0);
  EXPECT_EQ(scaled_first_frame_ms(125.0, 0.0, 100.0), 0.0);
}

TEST(FirstFrame, RefusedWithOneLineWhenItCannotFit) {
  // A budget far below one frame: --time 3 at 4000x4000.
  const std::string refusal = first_frame_refusal(30518.0, 600.0, 3000.0, 4000, 4000);
  ASSERT_FALSE(refusal.empty());
  EXPECT_EQ(refusal.find('\n'), std::string::npos);
  EXPECT_NE(refusal.find("4000x4000"), std::string::npos) << refusal;
  EXPECT_NE(refusal.find("--time"), std::string::npos) << refusal;
  // What fits is not refused, nor is a frame that ends exactly at the budget.
  EXPECT_EQ(first_frame_refusal(2000.0, 600.0, 3000.0, 4000, 4000), "");
  EXPECT_EQ(first_frame_refusal(2400.0, 600.0, 3000.0, 4000, 4000), "");
  // The time already spent (loading, the probe) counts.
  EXPECT_NE(first_frame_refusal(2000.0, 1500.0, 3000.0, 4000, 4000), "");
}

}  // namespace
}  // namespace pxf
