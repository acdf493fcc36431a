// The allocation of adaptive sampling (app/adaptive.h) under fake variance images: the need is the
// final pixel's perceived variance over its own threshold, pooled like the blend's; samples follow
// it up to one per frame; the floor, the minimum and the dilation hold.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "app/adaptive.h"

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
  std::vector<float> need(float t, const Image* range = nullptr, const Image* depth = nullptr) const {
    return final_pixel_need(lv, hv, var_u, var_lv, paths, t, range, depth, range_weights(FilterParams{}));
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

TEST(AdaptiveNeed, IsDecidedOnThePooledVarianceAsTheBlendDoes) {
  // A pixel that looks quiet among noisy neighbours of the same range takes their mean variance (3x3,
  // range-weighted): it has likely missed the rare paths they found. Across a range edge it keeps its own.
  FakeImages f(3, 3, 0.3f, 0.2f, 0.004f, 0.0f, 100);
  f.var_u.at(1, 1, 0) = 1e-6f;
  Image range = Image::rgb(3, 3), depth = Image::gray(3, 3);
  for (float& v : range.pixels) v = 0.5f;
  for (float& v : depth.pixels) v = 1.0f;
  const float t = 0.001f;
  const float pooled = f.need(t, &range, &depth)[4], own = f.need(t)[4];
  EXPECT_GT(pooled, 100.0f * own);
  for (int c = 0; c < 3; ++c) range.at(1, 1, c) = 0.0f;  // the centre shows another surface
  EXPECT_NEAR(f.need(t, &range, &depth)[4], own, 1e-3f * own);
}

// The pooling only raises a need, and every need above full_rate_need gives the same rate: a pixel
// whose own variance already puts it there skips the pooling, the others are pooled as before.
TEST(AdaptiveNeed, PoolingIsSkippedOnlyWhereTheOwnNeedIsAlreadyPastExactBelow) {
  FakeImages f(3, 3, 0.3f, 0.2f, 0.004f, 0.0f, 100);
  f.var_u.at(1, 1, 0) = 1e-6f;  // quiet centre: its own need is tiny, its pooled need large
  Image range = Image::rgb(3, 3), depth = Image::gray(3, 3);
  for (float& v : range.pixels) v = 0.5f;
  for (float& v : depth.pixels) v = 1.0f;
  const float t = 0.001f;
  const std::vector<float> all_pooled = f.need(t, &range, &depth);
  const std::vector<float> own = f.need(t);
  const std::vector<float> skipped =
      final_pixel_need(f.lv, f.hv, f.var_u, f.var_lv, f.paths, t, &range, &depth, range_weights(FilterParams{}), 4.0f);
  ASSERT_GE(own[0], 4.0f);           // the noisy corner is past the bound on its own
  EXPECT_EQ(skipped[0], own[0]);     // so it keeps its own need
  ASSERT_LT(own[4], 4.0f);           // the quiet centre is not
  EXPECT_EQ(skipped[4], all_pooled[4]);  // so it is pooled exactly as without the bound
  EXPECT_GT(skipped[4], 100.0f * own[4]);
}

TEST(AdaptiveDilation, EveryPixelInTheBoxTakesTheLargestNeed) {
  const int w = 9, h = 7;
  std::vector<float> need(w * h, 0.5f);
  need[3 * w + 4] = 20.0f;
  need[0] = 7.0f;
  const std::vector<float> d = dilate_need(need, w, h, 2);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const bool near_hot = std::abs(x - 4) <= 2 && std::abs(y - 3) <= 2;
      const bool near_corner = x <= 2 && y <= 2;
      const float expected = near_hot ? 20.0f : near_corner ? 7.0f : 0.5f;
      EXPECT_EQ(d[y * w + x], expected) << x << "," << y;
    }
  EXPECT_EQ(dilate_need(need, w, h, 0), need);
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

TEST(AdaptiveRates, ADilatedCausticKeepsItsQuietNeighboursSampled) {
  // The chain from a fake need image to the masks: a hot pixel (need 40) among clean ones (0.1) past
  // the minimum. Its 5x5 box is traced every frame, the rest at the floor.
  const int w = 12, h = 10;
  const AdaptiveParams params;
  std::vector<float> need(w * h, 0.1f);
  need[5 * w + 6] = 40.0f;
  const std::vector<float> rates =
      sampling_rates(dilate_need(need, w, h, params.dilation_radius), std::vector<uint32_t>(w * h, 500), params);
  const std::vector<int> traced = traced_over(rates, 32);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const bool in_box = std::abs(x - 6) <= 2 && std::abs(y - 5) <= 2;
      EXPECT_EQ(traced[y * w + x], in_box ? 32 : 2) << x << "," << y;
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
