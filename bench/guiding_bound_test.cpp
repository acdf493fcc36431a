// The guiding bound's variance formulas (guiding_bound.h) against the estimator they describe, run.
#include "bench/guiding_bound.h"

#include <cmath>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "pathtracer/rng.h"
#include "testing/shapes.h"

namespace pxf {
namespace {

// Cells whose radiance takes one of two values, `low` or `high` with probability `p_high`: the
// moments follow, and the estimator can be simulated exactly.
struct TwoValueCell {
  double share, low, high, p_high;
  DirectionCell moments(double guide_share) const {
    const double mean = low + p_high * (high - low);
    const double second = (1.0 - p_high) * low * low + p_high * high * high;
    return DirectionCell{share, guide_share, mean, second};
  }
};

std::vector<TwoValueCell> test_cells() {
  return {{0.4, 0.0, 0.1, 0.5}, {0.3, 0.2, 0.2, 0.0}, {0.2, 0.0, 5.0, 0.1}, {0.1, 1.0, 3.0, 0.5}};
}

std::vector<DirectionCell> moments(const std::vector<TwoValueCell>& cells, const std::vector<double>& guide) {
  std::vector<DirectionCell> out;
  for (size_t i = 0; i < cells.size(); ++i) out.push_back(cells[i].moments(guide[i]));
  return out;
}

// Draws the cell by q and its value, weighs by b / q: the sample variance over many draws.
double simulated_variance(const std::vector<TwoValueCell>& cells, const std::vector<double>& q, int draws) {
  Rng rng(3, 0, 0);
  double sum = 0.0, sum2 = 0.0;
  for (int d = 0; d < draws; ++d) {
    double u = rng.next_float(), x = 0.0;
    for (size_t i = 0; i < cells.size(); ++i) {
      if (u < q[i] || i + 1 == cells.size()) {
        const double value = rng.next_float() < cells[i].p_high ? cells[i].high : cells[i].low;
        x = value * cells[i].share / q[i];
        break;
      }
      u -= q[i];
    }
    sum += x;
    sum2 += x * x;
  }
  const double mean = sum / draws;
  return sum2 / draws - mean * mean;
}

TEST(GuidingBound, VarianceFormulaMatchesTheSimulatedEstimator) {
  const std::vector<TwoValueCell> cells = test_cells();
  const std::vector<double> field = {0.1, 0.1, 0.6, 0.2};
  const std::vector<DirectionCell> m = moments(cells, field);
  const std::vector<std::vector<double>> guides = {
      {0.4, 0.3, 0.2, 0.1}, field_guide(m, 0.5), known_light_guide(m, 0.5), least_variance_guide(m)};
  for (const std::vector<double>& q : guides) {
    double total = 0.0;
    for (double v : q) total += v;
    ASSERT_NEAR(total, 1.0, 1e-12);
    const double formula = cell_estimator_variance(m, q), simulated = simulated_variance(cells, q, 2000000);
    // 2e6 draws: the sample variance's relative standard error is below 1 % for these tails.
    EXPECT_NEAR(simulated / formula, 1.0, 0.03) << formula << " " << simulated;
  }
}

TEST(GuidingBound, GuidesOrderAsTheyShould) {
  const std::vector<DirectionCell> m = moments(test_cells(), {0.25, 0.25, 0.25, 0.25});
  const std::vector<double> cosine = {0.4, 0.3, 0.2, 0.1};
  const double v_cos = cell_estimator_variance(m, cosine);
  const double v_known = cell_estimator_variance(m, known_light_guide(m, 0.5));
  const double v_least = cell_estimator_variance(m, least_variance_guide(m));
  EXPECT_LT(v_least, v_known);
  EXPECT_LT(v_known, v_cos);
  // The least variance is (sum b sqrt(E[L^2]))^2 - mean^2, below every mixture of the others.
  double root = 0.0, mean = 0.0;
  for (const DirectionCell& c : m) {
    root += c.cosine_share * std::sqrt(c.second_moment);
    mean += c.cosine_share * c.mean;
  }
  EXPECT_NEAR(v_least, root * root - mean * mean, 1e-12);
  for (double alpha : {0.0, 0.3, 0.9}) EXPECT_GE(cell_estimator_variance(m, known_light_guide(m, alpha)), v_least);
  // A field with no guide share equals cosine sampling whatever alpha is 0.
  EXPECT_NEAR(cell_estimator_variance(m, field_guide(m, 0.0)), v_cos, 1e-12);
}

// The floor lies under every guide's variance, and on cells whose light does not vary within them
// it is the least over the cells. Directions drawn by cosine sampling, each with many paths.
TEST(GuidingBound, FloorLiesUnderEveryGuide) {
  const std::vector<TwoValueCell> two = test_cells();
  const std::vector<DirectionCell> m = moments(two, {0.1, 0.1, 0.6, 0.2});
  std::vector<double> second_moments, means;
  Rng rng(5, 0, 0);
  for (int i = 0; i < 20000; ++i) {
    double u = rng.next_float();
    size_t c = 0;
    while (c + 1 < m.size() && u >= m[c].cosine_share) u -= m[c++].cosine_share;
    double sum = 0.0, sum2 = 0.0;
    const int paths = 64;
    for (int j = 0; j < paths; ++j) {
      const double l = rng.next_float() < two[c].p_high ? two[c].high : two[c].low;
      sum += l;
      sum2 += l * l;
    }
    means.push_back(sum / paths);
    second_moments.push_back(sum2 / paths);
  }
  const double floor = guide_variance_floor(second_moments, means);
  const double least = cell_estimator_variance(m, least_variance_guide(m));
  EXPECT_GT(floor, 0.9 * least);  // the square roots of estimates from 64 paths read a little low
  const std::vector<std::vector<double>> guides = {
      {0.4, 0.3, 0.2, 0.1}, field_guide(m, 0.5), known_light_guide(m, 0.5), known_light_guide(m, 1.0),
      least_variance_guide(m), {0.25, 0.25, 0.25, 0.25}};
  for (const std::vector<double>& q : guides) EXPECT_LT(floor, cell_estimator_variance(m, q) * 1.001);
}

TEST(GuidingBound, LightKnownExactlyWithoutDeeperNoiseHasNoVariance) {
  // No noise within a cell: sampling exactly by b mean gives every sample the mean.
  std::vector<DirectionCell> m = {{0.5, 0, 0.0, 0.0}, {0.3, 0, 2.0, 4.0}, {0.2, 0, 0.5, 0.25}};
  EXPECT_NEAR(cell_estimator_variance(m, known_light_guide(m, 1.0)), 0.0, 1e-12);
  EXPECT_NEAR(cell_estimator_variance(m, least_variance_guide(m)), 0.0, 1e-12);
  // A cell with light that the guide never picks has no finite variance.
  EXPECT_TRUE(std::isinf(cell_estimator_variance(m, {1.0, 0.0, 0.0})));
}

// Inside a closed sphere whose walls glow (Le 1) and reflect half the light (albedo 0.5), radiance
// is the same everywhere and in every direction. The indirect light a direction brings (emission it
// sees directly left out) is 0.5 + 0.25 + 0.125 within the render's path length (6 vertices: the
// point's paths have 5), weighed by the point's albedo 0.5. Every direction brings the same light,
// so knowing it exactly gains nothing over cosine sampling.
TEST(GuidingBound, GlowingRoomHasItsSeriesOfBounces) {
  Scene scene;
  Material wall = make_diffuse(glm::vec3(0.5f));
  wall.emissive = glm::vec3(1.0f);
  scene.materials = {wall};
  scene.meshes.push_back(make_sphere(glm::vec3(0.0f), 2.0f, 0, 48, 24, /*inward=*/true));
  scene.camera = look_at_camera(glm::vec3(0.0f), glm::vec3(0, 0, -1), glm::vec3(0, 1, 0), 0.8f);
  TraceParams params;
  params.threads = 2;
  GuidingBoundSettings settings;
  settings.points = 3;
  settings.face_cells = 8;
  settings.paths_per_cell = 256;
  settings.train_frames = 3;
  settings.floor_directions = 256;
  settings.floor_paths = 32;
  const GuidingBound bound = measure_guiding_bound(scene, params, 16, 16, settings);
  EXPECT_FALSE(bound.chains_left_out);
  const std::vector<GuidingBoundPoint>& points = bound.points;
  ASSERT_EQ(points.size(), 3u);
  for (const GuidingBoundPoint& p : points) {
    EXPECT_NEAR(p.indirect, 0.5 * 0.875, 0.01);
    EXPECT_GT(p.cosine, 0.0);
    EXPECT_NEAR(p.known_light / p.cosine, 1.0, 0.05);
    EXPECT_LE(p.least, p.known_light);
    EXPECT_NEAR(p.deeper / p.cosine, 1.0, 0.05);  // all of the variance is the deeper vertices'
    // ... and the same in every direction, so the floor is that variance (the square roots of
    // estimates read a little low).
    std::printf("floor / cosine %.3f\n", p.floor / p.cosine);
    EXPECT_LT(p.floor, p.least);
    EXPECT_GT(p.floor / p.cosine, 0.8);
  }
}

// Where the renderer's first vertices also trace specular chains, the bound says it leaves them out.
TEST(GuidingBound, SaysWhenItLeavesTheChainsOut) {
  const Scene scene = make_cornell_box(true);
  TraceParams params;
  params.threads = 2;
  GuidingBoundSettings tiny;
  tiny.points = 1;
  tiny.face_cells = 2;
  tiny.paths_per_cell = 1;
  tiny.train_frames = 1;
  tiny.floor_directions = 1;
  tiny.floor_paths = 2;
  EXPECT_TRUE(measure_guiding_bound(scene, params, 8, 8, tiny).chains_left_out);
  params.specular_chains = false;
  EXPECT_FALSE(measure_guiding_bound(scene, params, 8, 8, tiny).chains_left_out);
}

}  // namespace
}  // namespace pxf
