// The allocation of adaptive sampling (preview/adaptive.h) under fake variance images: the need is the
// final pixel's perceived variance over its own threshold, decided for each pixel by the others in
// its box; the paths follow its standard deviation, water-filled to a uniform frame's paths (goal
// Error), or go to the pixels that lack least of the counts their neighbours predict first (goal
// Clean); the floor, the cap, the minimum and the dilation hold.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "preview/adaptive.h"
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
// own samples say, its weight is the same; its neighbours' weights follow it. (Its rate also
// depends, through the water filling, on the whole image's weights, to which it adds little.)
TEST(AdaptiveNeighbourhood, APixelsOwnNeedNeverDecidesItsWeight) {
  const int w = 7, h = 7;
  for (AdaptiveGoal goal : {AdaptiveGoal::Error, AdaptiveGoal::Clean}) {
    AdaptiveParams params;
    params.goal = goal;
    const std::vector<uint32_t> paths(w * h, 500);
    std::vector<float> need(w * h, 0.3f);
    need[2 * w + 2] = 6.0f;
    const size_t centre = 3 * w + 3;
    std::vector<std::vector<float>> weights, typical;  // goal Clean: the full and the typical lacks
    for (float own : {0.0f, 1.0f, 50.0f, kInf}) {
      need[centre] = own;
      if (goal == AdaptiveGoal::Error) {
        weights.push_back(allocation_weights(neighbourhood_need(need, w, h, params.dilation_radius), paths, params));
        continue;
      }
      std::vector<float> full, typ;
      for (const CleanLack& lack : clean_lacks(need, paths, w, h, params)) {
        full.push_back(lack.full);
        typ.push_back(lack.typical);
      }
      weights.push_back(full);
      typical.push_back(typ);
    }
    for (const auto& wt : weights) EXPECT_EQ(wt[centre], weights[0][centre]);
    for (const auto& typ : typical) EXPECT_EQ(typ[centre], typical[0][centre]);
    EXPECT_LT(weights[0][5 * w + 5], weights[2][5 * w + 5]);  // a neighbour's weight does follow it
  }
}

// Paths traced per pixel over `frames` frames of fixed rates.
std::vector<int> traced_over(const std::vector<float>& rates, int frames) {
  std::vector<float> credit;
  std::vector<int> traced(rates.size(), 0);
  for (int f = 0; f < frames; ++f) {
    const std::vector<uint8_t> counts = select_active(rates, credit);
    for (size_t p = 0; p < rates.size(); ++p) traced[p] += counts[p];
  }
  return traced;
}

double sum_of(const std::vector<float>& v) {
  double s = 0;
  for (float x : v) s += x;
  return s;
}

// Goal Error: paths in proportion to the per-path standard deviation sqrt(r n) (n proportional to
// sigma), every frame as many paths as a uniform one.
TEST(AdaptiveRates, ForTheErrorSamplesFollowTheStandardDeviation) {
  const AdaptiveParams params;  // goal Error
  const std::vector<float> need = {0.25f, 1.0f, 4.0f, 9.0f, 0.25f, 1.0f, 0.0f, 16.0f};
  std::vector<uint32_t> paths(need.size(), 1000);  // past the minimum
  paths[4] = 4000;  // four times the paths at the same need: twice the per-path deviation
  const std::vector<float> rates = sampling_rates(need, paths, params);
  EXPECT_NEAR(sum_of(rates), need.size() * params.frame_paths, 1e-3);
  EXPECT_NEAR(rates[1] / rates[0], 2.0f, 1e-4f);
  EXPECT_NEAR(rates[2] / rates[0], 4.0f, 1e-4f);
  EXPECT_NEAR(rates[3] / rates[0], 6.0f, 1e-4f);
  EXPECT_NEAR(rates[4] / rates[0], 2.0f, 1e-4f);
  EXPECT_EQ(rates[6], params.floor_rate);  // no need: the floor
  constexpr int kFrames = 256;
  const std::vector<int> traced = traced_over(rates, kFrames);
  for (size_t p = 0; p < need.size(); ++p) EXPECT_NEAR(traced[p], kFrames * rates[p], 1.0) << p;
}

// Goal Clean: each pixel lacks clean_margin times the largest count x_q = r_q n_q among the others
// of its box (the full count), and the median of them (the typical count), less its own paths, and
// at least the minimum.
TEST(AdaptiveRates, ForCleanEachPixelLacksItsNeighboursCounts) {
  AdaptiveParams params;
  params.goal = AdaptiveGoal::Clean;
  params.dilation_radius = 1;
  const int w = 8, h = 1;
    // x = r n:                      2000  400   1000  100   100   3000  100   100
  const std::vector<float> need = {2.0f, 0.4f, 1.0f, 0.1f, 0.1f, 3.0f, 0.1f, 0.1f};
  const std::vector<uint32_t> paths(need.size(), 1000);
  const std::vector<CleanLack> lacks = clean_lacks(need, paths, w, h, params);
  const float m = params.clean_margin;
  const std::vector<float> expected = {m * 400 - 1000, m * 2000 - 1000, m * 400 - 1000, m * 1000 - 1000,
                                       m * 3000 - 1000, m * 100 - 1000, m * 3000 - 1000, m * 100 - 1000};
  // In a row each pixel has one or two others: the median is the upper one, the largest.
  const std::vector<float> typical = {0, 1000, 0, 0, 2000, 0, 2000, 0};
  for (size_t p = 0; p < need.size(); ++p) {
    EXPECT_FLOAT_EQ(lacks[p].full, std::max(0.0f, expected[p])) << p;
    EXPECT_FLOAT_EQ(lacks[p].typical, typical[p]) << p;
  }
  // The pixel's own count is what it has: twice the paths, less lacking.
  std::vector<uint32_t> more = paths;
  more[1] = 2000;
  EXPECT_FLOAT_EQ(clean_lacks(need, more, w, h, params)[1].full, m * 2000 - 2000);
  // Below the minimum a pixel lacks at least the minimum, whatever its neighbours.
  const std::vector<uint32_t> young(need.size(), params.min_samples - 10);
  const CleanLack young_lack = clean_lacks(std::vector<float>(need.size(), 0.0f), young, w, h, params)[3];
  EXPECT_FLOAT_EQ(young_lack.full, 10.0f);
  EXPECT_FLOAT_EQ(young_lack.typical, 10.0f);
  // In a box of nine, the typical count is the median of the eight others (the upper one).
  std::vector<float> square(9, 0.0f);
  for (int q = 0; q < 9; ++q) square[q] = 0.1f * static_cast<float>(q + 1);  // x = 100, 200, ... 900
  const std::vector<uint32_t> square_paths(9, 1000);
  EXPECT_FLOAT_EQ(clean_lacks(square, square_paths, 3, 3, params)[4].typical, 0.0f);  // median 600 < 1000
  EXPECT_FLOAT_EQ(neighbourhood_median(square, 3, 3, 1)[4], 0.6f);
  EXPECT_FLOAT_EQ(neighbourhood_median(square, 3, 3, 1)[0], 0.4f);  // a corner's others: 0.2, 0.4, 0.5
}

// Shortest lack first: what the pixels lack of their typical counts, least first, then what they
// lack of their full counts beyond that, least full lack first, each share taken over the horizon
// (a pixel at most at the cap), until the budget is spent; the rest at the floor; a budget left
// after every lack raises the floor.
TEST(AdaptiveRates, ForCleanTheShortestLacksAreServedFirst) {
  const float floor_rate = 0.0625f, cap = 32.0f;
  //                                 typical, full
  const std::vector<CleanLack> lacks = {{0, 0}, {40, 400}, {0, 100}, {20, 900}, {0, 0}, {0, 50}, {200, 300}, {0, 0}};
  const double horizon = 10.0;
  // A budget of 8 paths a frame: the floor takes 0.5, pixel 3 (typical lack 20) 2 more, pixel 1 (40)
  // 4, and pixel 6 (200: 20 a frame) the last 1.5; the full lacks wait.
  const std::vector<float> rates = shortest_lack_first(lacks, 8.0, floor_rate, cap, horizon);
  EXPECT_NEAR(sum_of(rates), 8.0, 1e-5);
  EXPECT_NEAR(rates[3], floor_rate + 2.0f, 1e-6f);
  EXPECT_NEAR(rates[1], floor_rate + 4.0f, 1e-6f);
  EXPECT_NEAR(rates[6], floor_rate + 1.5f, 1e-5f);
  for (size_t p : {0, 2, 4, 5, 7}) EXPECT_EQ(rates[p], floor_rate) << p;
  // 50 paths: the typical lacks (26 a frame), then the full ones, least first: pixel 5 (5 a
  // frame), pixel 2 (10), and what is left (8.5) to pixel 6's last 100.
  const std::vector<float> more = shortest_lack_first(lacks, 50.0, floor_rate, cap, horizon);
  EXPECT_NEAR(more[5], floor_rate + 5.0f, 1e-5f);
  EXPECT_NEAR(more[2], floor_rate + 10.0f, 1e-5f);
  EXPECT_NEAR(more[6], floor_rate + 20.0f + 8.5f, 1e-4f);
  EXPECT_NEAR(more[1], floor_rate + 4.0f, 1e-5f);
  EXPECT_NEAR(more[3], floor_rate + 2.0f, 1e-5f);
  EXPECT_NEAR(sum_of(more), 50.0, 1e-4);
  // Past every lack, the rest goes to every pixel alike; the cap holds.
  const std::vector<float> ample = shortest_lack_first(lacks, 150.0, floor_rate, cap, horizon);
  EXPECT_NEAR(sum_of(ample), 150.0, 1e-3);
  EXPECT_EQ(ample[3], cap);  // 900 / 10 = 90 a frame, capped
  EXPECT_EQ(ample[1], cap);  // 40 a frame, capped
  EXPECT_NEAR(ample[0], 11.1875f, 1e-4f);  // the floor risen until the rates add up
  EXPECT_EQ(ample[0], ample[7]);
  // Nothing lacking: uniform.
  for (float r : shortest_lack_first(std::vector<CleanLack>(10), 10.0, floor_rate, cap, horizon)) EXPECT_NEAR(r, 1.0f, 1e-5f);
}

TEST(AdaptiveRates, WaterFillingKeepsTheCapAndTheFloorAndSpendsTheBudget) {
  std::vector<float> weights(100, 1.0f);
  weights[0] = 1e6f;                     // would take the whole budget: the cap
  weights[1] = kInf;                     // unknown variance: the cap
  for (size_t p = 2; p < 12; ++p) weights[p] = 0.0f;  // nothing to gain: the floor
  const std::vector<float> rates = water_fill(weights, 200.0, 0.0625f, 32.0f);
  EXPECT_EQ(rates[0], 32.0f);
  EXPECT_EQ(rates[1], 32.0f);
  for (size_t p = 2; p < 12; ++p) EXPECT_EQ(rates[p], 0.0625f);
  EXPECT_NEAR(sum_of(rates), 200.0, 1e-3);
  EXPECT_NEAR(rates[50], (200.0 - 64.0 - 10 * 0.0625) / 88.0, 1e-4);
  // Paths the weights cannot take go to every pixel alike: the floor rises.
  std::vector<float> few(100, 0.0f);
  few[7] = 1.0f;
  few[9] = 2.0f;
  const std::vector<float> spread = water_fill(few, 100.0, 0.0625f, 32.0f);
  EXPECT_EQ(spread[7], 32.0f);
  EXPECT_EQ(spread[9], 32.0f);
  EXPECT_NEAR(spread[0], 36.0 / 98.0, 1e-5);
  EXPECT_NEAR(sum_of(spread), 100.0, 1e-3);
  for (float r : water_fill(std::vector<float>(10, 0.0f), 10.0, 0.0625f, 32.0f)) EXPECT_NEAR(r, 1.0f, 1e-5f);
  // A budget past every cap: every pixel at the cap; below every floor: every pixel at the floor.
  for (float r : water_fill(weights, 1e6, 0.0625f, 32.0f)) EXPECT_EQ(r, 32.0f);
  for (float r : water_fill(std::vector<float>(10, 1.0f), 1e6, 0.0625f, 32.0f)) EXPECT_EQ(r, 32.0f);
  for (float r : water_fill(std::vector<float>(10, 1.0f), 0.1, 0.0625f, 32.0f)) EXPECT_EQ(r, 0.0625f);
}

TEST(AdaptiveRates, ARateAboveOneTracesSeveralPathsInAFrame) {
  std::vector<float> credit;
  const std::vector<float> rates = {2.5f, 0.25f, 40.0f};
  int total[3] = {0, 0, 0};
  for (int f = 0; f < 8; ++f) {
    const std::vector<uint8_t> counts = select_active(rates, credit);
    EXPECT_TRUE(counts[0] == 2 || counts[0] == 3) << f;
    EXPECT_EQ(counts[2], 40);
    for (int p = 0; p < 3; ++p) total[p] += counts[p];
  }
  EXPECT_EQ(total[0], 20);
  EXPECT_EQ(total[1], 2);
}

TEST(AdaptiveRates, TheFloorRevisitsEveryPixelRegularly) {
  const AdaptiveParams params;
  // Three pixels at the floor beside one that takes the rest of the budget.
  std::vector<float> rates = water_fill({0.0f, 0.0f, 0.0f, 1.0f}, 4.0, params.floor_rate, params.max_rate);
  EXPECT_NEAR(rates[3], 4.0 - 3 * params.floor_rate, 1e-5);
  rates.pop_back();
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
  for (AdaptiveGoal goal : {AdaptiveGoal::Error, AdaptiveGoal::Clean}) {
    AdaptiveParams params;
    params.goal = goal;
    const std::vector<float> need(16, 0.0f);
    std::vector<uint32_t> paths(16, params.min_samples);
    paths[0] = params.min_samples - 1;
    std::vector<float> weights = allocation_weights(need, paths, params);
    if (goal == AdaptiveGoal::Clean) {
      weights.clear();
      for (const CleanLack& lack : clean_lacks(need, paths, 4, 4, params)) weights.push_back(lack.full);
    }
    EXPECT_GT(weights[0], 0.0f);  // counts as at the threshold
    EXPECT_EQ(weights[1], 0.0f);  // at the minimum: may retire
    // Unsampled, it takes the frame's paths while the others sit at the floor.
    paths[0] = 0;
    const std::vector<float> rates = allocation_rates(need, paths, 4, 4, params);
    EXPECT_GT(rates[0], params.floor_rate);
    EXPECT_EQ(rates[1], params.floor_rate);
  }
}

TEST(AdaptiveRates, ACausticKeepsItselfAndItsQuietNeighboursSampled) {
  // The chain from a fake need image to the path counts: a 2x2 caustic (need 40) among clean
  // pixels (0.1) past the minimum. The caustic's pixels keep each other traced, and so is every
  // pixel within 2 of it: sqrt(400) = 20 times as often as the rest (goal Error), or, as all of
  // them lack the same count, they take every path the floor leaves, at the cap in order
  // (goal Clean).
  const int w = 12, h = 10;
  for (AdaptiveGoal goal : {AdaptiveGoal::Error, AdaptiveGoal::Clean}) {
    AdaptiveParams params;
    params.goal = goal;
    std::vector<float> need(w * h, 0.1f);
    for (int y = 5; y <= 6; ++y)
      for (int x = 6; x <= 7; ++x) need[y * w + x] = 40.0f;
    const std::vector<float> rates = allocation_rates(need, std::vector<uint32_t>(w * h, 500), w, h, params);
    const std::vector<int> traced = traced_over(rates, 32);
    const int near_count = 36, far_count = w * h - near_count;
    const double far_rate = goal == AdaptiveGoal::Error ? w * h / (near_count * 20.0 + far_count) : params.floor_rate;
    const double near_rate = 20.0 * far_rate;
    double near_sum = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const bool near = x >= 4 && x <= 9 && y >= 3 && y <= 8;
        if (near) near_sum += rates[y * w + x];
        if (goal == AdaptiveGoal::Error || !near) {
          EXPECT_NEAR(traced[y * w + x], 32 * (near ? near_rate : far_rate), 1.0) << x << "," << y;
        } else {
          EXPECT_LE(rates[y * w + x], params.max_rate);
        }
      }
    EXPECT_NEAR(near_sum, w * h - far_count * far_rate, 1e-3);
    if (goal == AdaptiveGoal::Clean) {
      EXPECT_EQ(rates[3 * w + 4], params.max_rate);  // the first near pixel
    }
  }
}

// Goal Clean over a whole render: a caustic's pixels and their neighbours all lack the same count,
// and the queue serves them in turn until each has it. The fake need falls as 1 / n, as a real
// one does, so the counts the neighbours predict stay put.
TEST(AdaptiveRates, ForCleanACausticIsServedUntilEachPixelHasItsCount) {
  const int w = 12, h = 10;
  AdaptiveParams params;
  params.goal = AdaptiveGoal::Clean;
  std::vector<float> per_path(w * h, 0.1f * 500);  // r n: the count each pixel needs
  for (int y = 5; y <= 6; ++y)
    for (int x = 6; x <= 7; ++x) per_path[y * w + x] = 40.0f * 500;
  std::vector<uint32_t> paths(w * h, 500);
  std::vector<float> credit;
  GrowingSchedule replans(500, params.replan_divisor);
  std::vector<float> rates;
  for (int frame = 500; frame < 20000; ++frame) {
    if (rates.empty() || replans.due(frame)) {
      std::vector<float> need(w * h);
      for (size_t p = 0; p < need.size(); ++p) need[p] = per_path[p] / static_cast<float>(paths[p]);
      rates = allocation_rates(need, paths, w, h, params);
      replans.done(frame);
    }
    const std::vector<uint8_t> counts = select_active(rates, credit);
    for (size_t p = 0; p < paths.size(); ++p) paths[p] += counts[p];
  }
  const float full = params.clean_margin * 40.0f * 500;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const bool near = x >= 4 && x <= 9 && y >= 3 && y <= 8;
      if (near) {
        EXPECT_GE(paths[y * w + x], full) << x << "," << y;
      } else {
        EXPECT_LT(paths[y * w + x], 0.5f * full) << x << "," << y;
      }
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
