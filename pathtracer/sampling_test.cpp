#include "pathtracer/sampling.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

namespace pxf {
namespace {

// Bins of every size around the switch from the linear count to the binary search, with empty
// bins first, inside and last; weights whose CDF lands on exact binary fractions so that u can
// sit exactly on a boundary.
std::vector<std::vector<float>> weight_sets() {
  std::vector<std::vector<float>> sets;
  for (size_t n = 1; n <= 12; ++n) {
    std::vector<float> w(n);
    for (size_t i = 0; i < n; ++i) w[i] = static_cast<float>((i * 7 + 3) % 5);  // 3 0 2 4 1 3 0 ...
    if (n > 2) w.front() = 0.0f;
    sets.push_back(w);
  }
  sets.push_back({1.0f, 0.0f, 1.0f, 2.0f});  // CDF 0, 1/4, 1/4, 1/2, 1
  sets.push_back({0.0f, 0.0f, 4.0f, 0.0f, 4.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 8.0f, 0.0f});
  return sets;
}

TEST(Distribution1D, SamplesEachBinInProportionToItsWeight) {
  constexpr int kSteps = 1 << 14;
  for (const std::vector<float>& weights : weight_sets()) {
    SCOPED_TRACE(::testing::PrintToString(weights));
    const Distribution1D dist(weights);
    ASSERT_TRUE(dist.valid());
    std::vector<int> counts(weights.size(), 0);
    size_t previous = 0;
    float previous_remapped = -1.0f;
    for (int k = 0; k < kSteps; ++k) {
      const float u = (k + 0.5f) / kSteps;
      float remapped = -1.0f, pmf = -1.0f;
      const size_t i = dist.sample(u, &remapped, &pmf);
      ASSERT_LT(i, weights.size());
      EXPECT_GT(weights[i], 0.0f) << "u " << u << " picked an empty bin";
      EXPECT_EQ(pmf, dist.pmf(i));
      EXPECT_GE(remapped, 0.0f);
      EXPECT_LT(remapped, 1.0f);
      EXPECT_GE(i, previous) << "u " << u << ": the bins must follow u in order";
      if (i == previous) {
        EXPECT_GE(remapped, previous_remapped) << "u " << u;
      }
      previous = i;
      previous_remapped = remapped;
      ++counts[i];
    }
    double total = 0.0;
    for (float w : weights) total += w;
    for (size_t i = 0; i < weights.size(); ++i)
      EXPECT_NEAR(counts[i] / static_cast<double>(kSteps), weights[i] / total, 1.0 / kSteps) << "bin " << i;
  }
}

TEST(Distribution1D, UOnABoundaryPicksTheBinThatStartsThere) {
  const Distribution1D dist(std::vector<float>{1.0f, 0.0f, 1.0f, 2.0f});  // CDF 0, 1/4, 1/4, 1/2, 1
  float remapped = -1.0f;
  EXPECT_EQ(dist.sample(0.0f, &remapped), 0u);
  EXPECT_EQ(remapped, 0.0f);
  EXPECT_EQ(dist.sample(0.25f, &remapped), 2u);  // not the empty bin 1 that also starts at 1/4
  EXPECT_EQ(remapped, 0.0f);
  EXPECT_EQ(dist.sample(0.5f, &remapped), 3u);
  EXPECT_EQ(remapped, 0.0f);
  EXPECT_EQ(dist.sample(0x1.fffffep-1f, &remapped), 3u);
  EXPECT_LT(remapped, 1.0f);
}

TEST(SortedUpperBound, MatchesStdUpperBound) {
  // Sorted arrays of every length up to 70 and a long one, with runs of equal entries (empty bins)
  // and both search paths (counted, halved); u on every entry, just beside it, between entries,
  // outside [0, 1] and NaN.
  for (size_t n : {0, 1, 2, 3, 5, 8, 9, 10, 11, 16, 17, 31, 33, 64, 70, 1025}) {
    std::vector<float> sorted(n);
    for (size_t i = 0; i < n; ++i) sorted[i] = static_cast<float>((i / 3) * 3) / static_cast<float>(n + 1);
    std::vector<float> us = {std::nanf(""), -1.0f, 0.0f, 1.0f, 2.0f, std::numeric_limits<float>::infinity()};
    for (float c : sorted)
      for (float u : {c, std::nextafter(c, -1.0f), std::nextafter(c, 2.0f), c + 0.5f / static_cast<float>(n + 1)})
        us.push_back(u);
    for (size_t count_up_to : {size_t{0}, size_t{9}})
      for (float u : us) {
        const size_t want = static_cast<size_t>(std::upper_bound(sorted.begin(), sorted.end(), u) - sorted.begin());
        ASSERT_EQ(sorted_upper_bound(sorted.data(), n, u, count_up_to), want)
            << "n " << n << " u " << u << " count_up_to " << count_up_to;
      }
  }
}

// Large distributions sample through a guide table: every u picks the bin the full search in the
// CDF picks (runs of empty bins, a spike, exact binary fractions, u on and beside each CDF entry).
TEST(Distribution1D, GuideTablePicksTheBinsOfTheFullSearch) {
  for (size_t n : {size_t{64}, size_t{100}, size_t{1024}, size_t{1500}}) {
    std::vector<float> weights(n);
    for (size_t i = 0; i < n; ++i) weights[i] = (i / 7) % 3 == 0 ? 0.0f : static_cast<float>((i * 13) % 11);
    weights[n / 3] = 1e5f;  // a sun
    const Distribution1D dist(weights);
    std::vector<float> us;
    for (int k = 0; k < 20000; ++k) us.push_back((k + 0.37f) / 20000.0f);
    for (size_t i = 0; i <= n; i += 3) {
      const float c = static_cast<float>(i) / static_cast<float>(n);
      us.insert(us.end(), {c, std::nextafter(c, 0.0f), std::nextafter(c, 1.0f)});
    }
    // The full search's answer, from the CDF Distribution1D builds (doubles, normalized to floats).
    std::vector<double> sums(n + 1, 0.0);
    for (size_t i = 0; i < n; ++i) sums[i + 1] = sums[i] + weights[i];
    std::vector<float> cdf(n + 1);
    for (size_t i = 0; i <= n; ++i) cdf[i] = static_cast<float>(sums[i] / sums[n]);
    cdf[n] = 1.0f;
    for (float u : us) {
      size_t want = sorted_upper_bound(cdf.data(), cdf.size(), u, 0);
      want = std::min(want == 0 ? size_t{0} : want - 1, n - 1);
      while (weights[want] == 0.0f && want + 1 < n) ++want;
      ASSERT_EQ(dist.sample(u), want) << "n " << n << " u " << u;
    }
  }
}

TEST(Distribution1D, NonFiniteUStillPicksABin) {
  for (const std::vector<float>& weights : weight_sets()) {
    const Distribution1D dist(weights);
    for (float u : {std::nanf(""), std::numeric_limits<float>::infinity(), -1.0f, 2.0f}) {
      float remapped = -1.0f;
      const size_t i = dist.sample(u, &remapped);
      EXPECT_LT(i, weights.size());
      EXPECT_FALSE(remapped < 0.0f || remapped >= 1.0f) << "u " << u;
    }
  }
}

// Distribution2D keeps its rows in flat arrays: every sample (position and pdf) is the one of a
// marginal over the rows' totals and one Distribution1D per row, bit for bit, with rows that hold
// no light (their guide tables left empty) and rows too short for a guide table.
TEST(Distribution2D, FlatRowsSampleAsOneDistributionPerRow) {
  for (int width : {5, 100, 1024}) {
    const int height = 9;
    std::vector<float> weights(static_cast<size_t>(width) * height);
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x)
        weights[static_cast<size_t>(y) * width + x] =
            y == 0 || y == 4 || y == height - 1 ? 0.0f : static_cast<float>((x * 7 + y * 3) % 5) * (x == width / 2 ? 1e4f : 1.0f);
    const Distribution2D dist(weights, width, height);
    std::vector<Distribution1D> rows;
    std::vector<float> totals;
    for (int y = 0; y < height; ++y) {
      rows.emplace_back(weights.data() + static_cast<size_t>(y) * width, width);
      totals.push_back(static_cast<float>(rows.back().total()));
    }
    const Distribution1D marginal(totals);
    for (int k = 0; k < 4000; ++k) {
      const glm::vec2 u((k * 0.6180339887f) - std::floor(k * 0.6180339887f), (k + 0.5f) / 4000.0f);
      float pdf, uy, ux, pmf_y, pmf_x;
      const glm::vec2 uv = dist.sample(u, &pdf);
      const size_t y = marginal.sample(u.y, &uy, &pmf_y);
      const size_t x = rows[y].sample(u.x, &ux, &pmf_x);
      ASSERT_EQ(uv, glm::vec2((static_cast<float>(x) + ux) / width, (static_cast<float>(y) + uy) / height)) << k;
      ASSERT_EQ(pdf, pmf_y * pmf_x * static_cast<float>(width) * static_cast<float>(height)) << k;
      ASSERT_EQ(dist.pdf(uv), pdf) << k;
    }
  }
}

}  // namespace
}  // namespace pxf
