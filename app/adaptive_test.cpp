// The allocation of adaptive sampling (app/adaptive.h) under fake variance images: the need is the
// final pixel's perceived variance over its own threshold, decided for each pixel by the others in its box; samples follow
// it up to one per frame; the floor, the minimum and the dilation hold.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "app/adaptive.h"
#include "gl/pass_params.h"

namespace pxf {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// A flat w x h image: L_lv = lv, L_u = hv (grey), variances var_u and var_lv everywhere.
struct FakeImages {
  Image lv, hv, var_u, var_lv;
  std::vector<uint32_t> paths;
  FakeImages(int w, int h, float lv_value, float hv_value, float vu, float vl, uint32_t n)
      : lv(Image::rgb(w, h)), hv(Image::rgb(w, h)), var_u(Image::gray(w, h)), var_lv(Image::gray(w, h)),
        paths(static_cast<size_t>(w) * h, n) {
    for (float& v : lv.pixels) v = lv_value;
    for (float& v : hv.pixels) v = hv_value;
    for (float& v : var_u.pixels) v = vu;
    for (float& v : var_lv.pixels) v = vl;
  }
  std::vector<float> need(float t) const {
    return final_pixel_need(lv, hv, var_u, var_lv, paths, t);
  }
};

TEST(AdaptiveNeed, IsTheFinalPixelsPerceivedVarianceOverItsOwnThreshold) {
  // L_b = Y(0.3) + Y(0.2) = 0.5; V = Var[L_u] + Var[L_lv] = 0.001 + 0.0005.
  FakeImages f(3, 2, 0.3f, 0.2f, 0.001f, 0.0005f, 100);
  f.paths[4] = 10;  // a pixel with fewer samples has a lower threshold: a larger need
  const float t = 0.002f;
  const std::vector<float> need = f.need(t);
  const float q = 0.0015f / (0.5f * 0.5f);
  EXPECT_NEAR(need[0], q / effective_threshold(t, 100), 1e-4f * need[0]);
  EXPECT_NEAR(need[4], q / effective_threshold(t, 10), 1e-4f * need[4]);
  EXPECT_GT(need[4], need[0]);
  // LV's variance counts: without it the need is a third lower.
  FakeImages no_lv_noise(3, 2, 0.3f, 0.2f, 0.001f, 0.0f, 100);
  EXPECT_NEAR(no_lv_noise.need(t)[0], need[0] * 2.0f / 3.0f, 1e-4f * need[0]);
}

TEST(AdaptiveNeed, UnknownVarianceMustBeSampledAndZeroIsNoNeed) {
  FakeImages f(2, 1, 0.3f, 0.2f, 0.001f, 0.0f, 50);
  f.var_u.pixels[0] = -1.0f;  // n < 2
  f.var_u.pixels[1] = 0.0f;   // all samples equal, nothing known around
  const std::vector<float> need = f.need(0.001f);
  EXPECT_EQ(need[0], kInf);
  EXPECT_EQ(need[1], 0.0f);
}

TEST(AdaptiveNeighbourhood, EachPixelTakesTheLargestNeedOfTheOthersInItsBox) {
  const int w = 9, h = 7;
  std::vector<float> need(w * h, 0.5f);
  need[3 * w + 4] = 20.0f;
  need[0] = 7.0f;
  const std::vector<float> d = neighbourhood_need(need, w, h, 2);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const bool hot = x == 4 && y == 3, corner = x == 0 && y == 0;
      const bool near_hot = std::abs(x - 4) <= 2 && std::abs(y - 3) <= 2 && !hot;
      const bool near_corner = x <= 2 && y <= 2 && !corner;
      const float expected = near_hot ? 20.0f : near_corner ? 7.0f : 0.5f;
      EXPECT_EQ(d[y * w + x], expected) << x << "," << y;
    }
  EXPECT_EQ(neighbourhood_need(need, w, h, 0), std::vector<float>(w * h, 0.0f));  // no others
}

// The property that keeps adaptive means unbiased (tests/consistency_test.cpp): whatever a pixel's
// own samples say, its rate is the same; its neighbours' rates follow it. (With full_rate_share the
// scale is the need at the top quarter of all pixels, to which each pixel adds 1/N: off here.)
TEST(AdaptiveNeighbourhood, APixelsOwnNeedNeverDecidesItsRate) {
  const int w = 7, h = 7;
  AdaptiveParams params;
  params.full_rate_share = 0.0f;
  const std::vector<uint32_t> paths(w * h, 500);
  std::vector<float> need(w * h, 0.3f);
  need[2 * w + 2] = 6.0f;
  const size_t centre = 3 * w + 3;
  std::vector<std::vector<float>> rates;
  for (float own : {0.0f, 1.0f, 50.0f, kInf}) {
    need[centre] = own;
    rates.push_back(sampling_rates(neighbourhood_need(need, w, h, params.dilation_radius), paths, params));
  }
  for (const auto& r : rates) EXPECT_EQ(r[centre], rates[0][centre]);
  EXPECT_LT(rates[0][5 * w + 5], rates[2][5 * w + 5]);  // a neighbour's rate does follow it
}

// Frames traced per pixel over `frames` frames of fixed rates.
std::vector<int> traced_over(const std::vector<float>& rates, int frames) {
  std::vector<float> credit;
  std::vector<int> traced(rates.size(), 0);
  for (int f = 0; f < frames; ++f) {
    const std::vector<uint8_t> active = select_active(rates, credit);
    for (size_t p = 0; p < rates.size(); ++p) traced[p] += active[p];
  }
  return traced;
}

TEST(AdaptiveRates, SamplesFollowTheNeedUpToOnePerFrame) {
  AdaptiveParams params;
  params.full_rate_share = 0.0f;  // the fixed scale full_rate_need (the share: the next test)
  const std::vector<float> need = {0.5f, 1.0f, 2.0f, 3.0f, 4.0f, 30.0f, kInf};
  const std::vector<uint32_t> paths(need.size(), 1000);  // past the minimum
  const std::vector<float> rates = sampling_rates(need, paths, params);
  constexpr int kFrames = 256;
  const std::vector<int> traced = traced_over(rates, kFrames);
  for (size_t p = 0; p < need.size(); ++p) {
    const double expected = kFrames * std::min(1.0, static_cast<double>(need[p] / params.full_rate_need));
    EXPECT_NEAR(traced[p], expected, 1.0) << "need " << need[p];
  }
  // Proportional: twice the need, twice the samples (below a path per frame).
  EXPECT_NEAR(static_cast<double>(traced[2]) / traced[1], 2.0, 0.02);
  EXPECT_NEAR(static_cast<double>(traced[3]) / traced[0], 6.0, 0.1);
}

// While most pixels are far from t, only the neediest full_rate_share of them are traced every frame
// and the others in proportion to their need; once few are past full_rate_need, the fixed scale holds.
TEST(AdaptiveRates, TheNeediestShareIsTracedEveryFrameTheOthersInProportion) {
  AdaptiveParams params;  // full_rate_share 0.25
  std::vector<float> need(100);
  for (size_t p = 0; p < need.size(); ++p) need[p] = 10.0f + static_cast<float>(p);  // 10 .. 109, all past 4
  const std::vector<uint32_t> paths(need.size(), 1000);
  const std::vector<float> rates = sampling_rates(need, paths, params);
  const float scale = need[75];  // the pixel with 25 pixels above it
  for (size_t p = 0; p < need.size(); ++p)
    EXPECT_FLOAT_EQ(rates[p], std::min(1.0f, need[p] / scale)) << p;
  EXPECT_EQ(std::count(rates.begin(), rates.end(), 1.0f), 25);
  // Few pixels past full_rate_need: the scale stays full_rate_need.
  std::vector<float> mostly_clean(100, 0.5f);
  mostly_clean[7] = 40.0f;
  const std::vector<float> clean_rates = sampling_rates(mostly_clean, paths, params);
  EXPECT_EQ(clean_rates[7], 1.0f);
  EXPECT_FLOAT_EQ(clean_rates[0], 0.5f / params.full_rate_need);
  // Unknown variances (infinite need) are traced every frame and do not make the scale infinite.
  std::vector<float> unknown(need);
  for (size_t p = 0; p < 40; ++p) unknown[p] = kInf;
  const std::vector<float> unknown_rates = sampling_rates(unknown, paths, params);
  EXPECT_EQ(unknown_rates[0], 1.0f);
  EXPECT_GT(unknown_rates[99], params.floor_rate);
}

TEST(AdaptiveRates, TheFloorRevisitsEveryPixelRegularly) {
  const AdaptiveParams params;
  const std::vector<float> need = {0.0f, 1e-6f, 0.05f};
  const std::vector<float> rates = sampling_rates(need, std::vector<uint32_t>(3, 1000), params);
  for (float r : rates) EXPECT_EQ(r, params.floor_rate);
  std::vector<float> credit;
  std::vector<int> last(3, -1);
  const int period = static_cast<int>(std::lround(1.0f / params.floor_rate));
  for (int f = 0; f < 10 * period; ++f) {
    const std::vector<uint8_t> active = select_active(rates, credit);
    for (size_t p = 0; p < 3; ++p)
      if (active[p]) {
        if (last[p] >= 0) {
          EXPECT_EQ(f - last[p], period);
        }
        last[p] = f;
      }
  }
  for (int l : last) EXPECT_GE(l, 9 * period - 1);
}

TEST(AdaptiveRates, APixelBelowTheMinimumIsNotRetired) {
  AdaptiveParams params;
  params.full_rate_share = 0.0f;
  const std::vector<float> need = {0.0f, 0.0f, 8.0f};
  const std::vector<uint32_t> paths = {params.min_samples - 1, params.min_samples, params.min_samples - 1};
  const std::vector<float> rates = sampling_rates(need, paths, params);
  EXPECT_EQ(rates[0], 1.0f / params.full_rate_need);  // counts as at the threshold
  EXPECT_EQ(rates[1], params.floor_rate);             // at the minimum: may retire
  EXPECT_EQ(rates[2], 1.0f);                          // a larger need stays
  params.min_samples = 0;
  EXPECT_EQ(sampling_rates(need, paths, params)[0], params.floor_rate);
}

TEST(AdaptiveRates, ACausticKeepsItselfAndItsQuietNeighboursSampled) {
  // The chain from a fake need image to the masks: a 2x2 caustic (need 40) among clean pixels (0.1)
  // past the minimum. The caustic's pixels keep each other traced every frame, and so is every pixel
  // within 2 of it; the rest is at the floor.
  const int w = 12, h = 10;
  const AdaptiveParams params;
  std::vector<float> need(w * h, 0.1f);
  for (int y = 5; y <= 6; ++y)
    for (int x = 6; x <= 7; ++x) need[y * w + x] = 40.0f;
  const std::vector<float> rates = sampling_rates(neighbourhood_need(need, w, h, params.dilation_radius),
                                                  std::vector<uint32_t>(w * h, 500), params);
  const std::vector<int> traced = traced_over(rates, 32);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const bool near = x >= 4 && x <= 9 && y >= 3 && y <= 8;
      EXPECT_EQ(traced[y * w + x], near ? 32 : 2) << x << "," << y;
    }
}

TEST(AdaptiveCounts, MeanMinAndMax) {
  const SampleCounts c = sample_counts({4, 8, 16, 4});
  EXPECT_DOUBLE_EQ(c.mean, 8.0);
  EXPECT_EQ(c.min, 4u);
  EXPECT_EQ(c.max, 16u);
}

}  // namespace
}  // namespace pxf
