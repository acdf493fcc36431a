#include "pathtracer/guiding_field.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <random>
#include <stdexcept>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "pathtracer/rng.h"
#include "pathtracer/sampling.h"
#include "testing/stat_tests.h"

namespace pxf {
namespace {

constexpr double kPiD = 3.14159265358979323846;
constexpr float kUniformPdf = float(1.0 / (4.0 * kPiD));
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

// The test's own cylindrical map (not the field's): (cos theta, phi) <-> [0,1)^2.
glm::vec3 direction_at(double u, double v) {
  const double z = 2.0 * u - 1.0, r = std::sqrt(std::max(0.0, 1.0 - z * z)), phi = 2.0 * kPiD * v;
  return glm::vec3(float(r * std::cos(phi)), float(r * std::sin(phi)), float(z));
}
glm::dvec2 square_at(glm::vec3 d) {
  d = glm::normalize(d);
  double phi = std::atan2(double(d.y), double(d.x));
  if (phi < 0.0) phi += 2.0 * kPiD;
  return glm::dvec2(0.5 * (double(d.z) + 1.0), phi / (2.0 * kPiD));
}

// Incident radiance: cones of constant radiance over a constant background.
struct Lobe {
  glm::vec3 axis;
  float cos_half_angle;
  float radiance;
};
struct Lighting {
  std::vector<Lobe> lobes;
  float background = 0.0f;
  float operator()(glm::vec3 d) const {
    float radiance = background;
    for (const Lobe& lobe : lobes)
      if (glm::dot(d, lobe.axis) > lobe.cos_half_angle) radiance += lobe.radiance;
    return radiance;
  }
};

// A cone holding `fraction` of the energy of its lighting, the rest spread uniformly.
Lighting cone_lighting(glm::vec3 axis, float half_angle_degrees, float fraction) {
  const float cos_half = std::cos(glm::radians(half_angle_degrees));
  const float cone_solid_angle = 2.0f * float(kPiD) * (1.0f - cos_half);
  const float background = (1.0f - fraction) / (4.0f * float(kPiD) - cone_solid_angle);
  return Lighting{{{glm::normalize(axis), cos_half, fraction / cone_solid_angle - background}}, background};
}

float fraction_in_cone(const GuidingField& field, glm::vec3 position, const Lobe& lobe, int samples, uint64_t seed) {
  Rng rng(seed, 1, 2);
  int inside = 0;
  for (int i = 0; i < samples; ++i) {
    float pdf;
    inside += glm::dot(field.sample(position, rng.next_2d(), &pdf), lobe.axis) > lobe.cos_half_angle;
  }
  return float(inside) / float(samples);
}

// One iteration as the integrator will run it: directions sampled from the field, weight 1 / pdf.
void train_iteration(GuidingField& field, const std::function<glm::vec3(Rng&)>& position, const Lighting& lighting,
                     int records, uint64_t seed) {
  Rng rng(seed, 7, uint64_t(field.iteration()));
  for (int i = 0; i < records; ++i) {
    const glm::vec3 p = position(rng);
    float pdf = 0.0f;
    const glm::vec3 d = field.sample(p, rng.next_2d(), &pdf);
    field.record(uint64_t(i), p, d, lighting(d), 1.0f / pdf);
  }
  field.end_iteration();
}

void train(GuidingField& field, glm::vec3 position, const Lighting& lighting, int iterations, int records) {
  for (int k = 0; k < iterations; ++k) train_iteration(field, [&](Rng&) { return position; }, lighting, records, 11);
}

struct ChiSquareCheck {
  stat::ChiSquareResult result;
  double probability_sum = 0.0;  // pdf() integrated over the sphere
};

// Pearson's chi-square of sample() against pdf() integrated over a 32 x 64 grid of (cos theta, phi).
// The integral is the midpoint rule on a 1024 x 1024 grid of the square: exact for quadtrees of at
// most 10 levels (every grid cell then lies in one quadrant), which the callers check.
ChiSquareCheck chi_square_of(const GuidingField& field, glm::vec3 position, int samples, uint64_t seed) {
  constexpr int kRows = 32, kCols = 64, kGrid = 1024;
  ChiSquareCheck check;
  std::vector<double> expected(kRows * kCols, 0.0), observed(kRows * kCols, 0.0);
  const double cell = 4.0 * kPiD / (double(kGrid) * kGrid);  // solid angle of a grid cell
  for (int i = 0; i < kGrid; ++i)
    for (int j = 0; j < kGrid; ++j) {
      const double p = field.pdf(position, direction_at((i + 0.5) / kGrid, (j + 0.5) / kGrid)) * cell;
      expected[(i * kRows / kGrid) * kCols + j * kCols / kGrid] += p;
      check.probability_sum += p;
    }
  for (double& e : expected) e *= samples;
  Rng rng(seed, 3, 4);
  for (int s = 0; s < samples; ++s) {
    float pdf = 0.0f;
    const glm::dvec2 uv = square_at(field.sample(position, rng.next_2d(), &pdf));
    const int row = std::min(int(uv.x * kRows), kRows - 1), col = std::min(int(uv.y * kCols), kCols - 1);
    observed[row * kCols + col] += 1.0;
  }
  check.result = stat::chi_square(observed, expected, 5.0);
  return check;
}

void expect_matches_pdf(const GuidingField& field, glm::vec3 position) {
  ASSERT_LE(field.stats().max_sampling_level, 10) << "the chi-square's integration is exact to 10 levels only";
  const ChiSquareCheck check = chi_square_of(field, position, 200000, 5);
  EXPECT_NEAR(check.probability_sum, 1.0, 1e-5);
  EXPECT_TRUE(check.result.problem.empty()) << check.result.problem;
  EXPECT_GT(check.result.p_value, 0.01) << "chi2 " << check.result.statistic << " dof " << check.result.dof;
}

TEST(GuidingField, UntrainedFieldIsUniform) {
  GuidingField field(glm::vec3(-1.0f), glm::vec3(1.0f));
  EXPECT_FALSE(field.trained());
  for (glm::vec3 d : {glm::vec3(0, 0, 1), glm::vec3(0, 0, -1), glm::vec3(1, 2, 3), glm::vec3(-5, 0, 0)})
    EXPECT_FLOAT_EQ(field.pdf(glm::vec3(0.3f), d), kUniformPdf);
  expect_matches_pdf(field, glm::vec3(0.3f));
}

TEST(GuidingField, SamplesFollowPdfForAPeakedLobe) {
  GuidingField field(glm::vec3(-1.0f), glm::vec3(1.0f));
  train(field, glm::vec3(0.2f), cone_lighting(glm::vec3(1, 2, 0.5f), 15.0f, 0.9f), 3, 20000);
  EXPECT_TRUE(field.trained());
  expect_matches_pdf(field, glm::vec3(0.2f));
}

TEST(GuidingField, SamplesFollowPdfForSeveralLobes) {
  // One lobe at the pole (where phi degenerates), one across phi = 0 (the square's seam), one broad.
  const Lighting lighting{{{glm::normalize(glm::vec3(0.05f, 0.0f, 1.0f)), std::cos(glm::radians(12.0f)), 40.0f},
                           {glm::normalize(glm::vec3(1.0f, 0.0f, -0.3f)), std::cos(glm::radians(10.0f)), 30.0f},
                           {glm::normalize(glm::vec3(-1.0f, -1.0f, 0.0f)), std::cos(glm::radians(40.0f)), 2.0f}},
                          0.05f};
  GuidingField field(glm::vec3(-1.0f), glm::vec3(1.0f));
  train(field, glm::vec3(-0.4f), lighting, 3, 20000);
  expect_matches_pdf(field, glm::vec3(-0.4f));
}

TEST(GuidingField, SampledPdfIsThePdfOfTheDirection) {
  // Nine records in ten from a cone of 0.01 degrees: quadrants down to the deepest levels, where
  // the float direction may round across a quadrant's edge.
  GuidingField field(glm::vec3(-1.0f), glm::vec3(1.0f));
  const Frame frame = Frame::from_normal(glm::normalize(glm::vec3(0.3f, -1.0f, 0.2f)));
  const float cos_max = std::cos(glm::radians(0.01f));
  for (int k = 0; k < 6; ++k) {
    Rng rng(8, 8, uint64_t(k));
    for (int i = 0; i < 20000; ++i) {
      const glm::vec2 u = rng.next_2d();
      const float cos_theta = 1.0f - u.x * (1.0f - cos_max), sin_theta = std::sqrt(1.0f - cos_theta * cos_theta);
      const glm::vec3 d(sin_theta * std::cos(6.2831853f * u.y), sin_theta * std::sin(6.2831853f * u.y), cos_theta);
      field.record(uint64_t(i), glm::vec3(0.0f), i % 10 ? frame.to_world(d) : glm::vec3(u.x - 0.5f, u.y - 0.5f, 0.1f), 1.0f, 1.0f);
    }
    field.end_iteration();
  }
  EXPECT_GE(field.stats().max_sampling_level, 16);
  Rng rng(9, 9, 9);
  int in_cone = 0;
  double solid_angle = 0.0;  // E[1 / pdf] = the sphere's 4 pi, however the density is spread
  for (int i = 0; i < 100000; ++i) {
    float pdf = -1.0f;
    const glm::vec3 d = field.sample(glm::vec3(0.0f), rng.next_2d(), &pdf);
    ASSERT_NEAR(glm::length(d), 1.0f, 1e-6f);
    ASSERT_TRUE(std::isfinite(pdf) && pdf > 0.0f);
    ASSERT_EQ(pdf, field.pdf(glm::vec3(0.0f), d));
    ASSERT_EQ(pdf, field.pdf(glm::vec3(0.0f), 2.0f * d));  // any length (2 d: the same direction exactly)
    in_cone += glm::dot(d, frame.n) > std::cos(glm::radians(0.05f));
    solid_angle += 1.0 / pdf / 100000;
  }
  EXPECT_GT(in_cone, 80000);
  // A sample drawn in a tiny bright quadrant but given the density of its dark neighbour (the
  // float direction rounded across the edge) would add 1 / pdf of the dark side: far too much.
  EXPECT_NEAR(solid_angle, 4.0 * kPiD, 0.05 * 4.0 * kPiD);
}

TEST(GuidingField, LearnsWhereTheLightComesFrom) {
  const glm::vec3 axis = glm::normalize(glm::vec3(-0.5f, 0.3f, 0.6f));
  const Lighting lighting = cone_lighting(axis, 5.0f, 0.9f);
  GuidingField field(glm::vec3(-1.0f), glm::vec3(1.0f));
  const glm::vec3 p(0.5f, 0.5f, -0.5f);
  EXPECT_LT(fraction_in_cone(field, p, lighting.lobes[0], 20000, 1), 0.01f);  // uniform: the cone is 0.2 % of the sphere
  train(field, p, lighting, 1, 20000);
  const float after_one = fraction_in_cone(field, p, lighting.lobes[0], 20000, 1);
  train(field, p, lighting, 2, 20000);
  const float after_three = fraction_in_cone(field, p, lighting.lobes[0], 20000, 1);
  EXPECT_GT(field.pdf(p, axis), 100.0f * kUniformPdf);
  EXPECT_GT(after_three, 0.75f);  // of the 0.9 of the energy there, times 0.99 guided
  EXPECT_GT(after_three, after_one);
  EXPECT_LT(field.pdf(p, -axis), kUniformPdf);  // the dark side
}

TEST(GuidingField, SplitsBusyRegionsAndLeavesQuietOnesAlone) {
  GuidingSettings settings;
  settings.spatial_threshold = 100.0f;
  GuidingField field(glm::vec3(-1.0f), glm::vec3(1.0f), settings);
  const glm::vec3 busy(-0.6f, 0.3f, 0.3f), quiet(0.6f, -0.3f, -0.3f);
  const auto feed = [&](int busy_records, int quiet_records) {
    uint64_t key = 0;
    for (int i = 0; i < busy_records; ++i) field.record(key++, busy, glm::vec3(0, 0, 1), 1.0f, 1.0f);
    for (int i = 0; i < quiet_records; ++i) field.record(key++, quiet, glm::vec3(0, 0, 1), 1.0f, 1.0f);
    field.end_iteration();
  };
  feed(140, 10);  // 150 > 100: the root splits along x, each half counted 75
  ASSERT_EQ(field.stats().spatial_leaves, 2u);
  feed(1000, 10);  // threshold 100 sqrt(2): 1000 -> 500 -> 250 -> 125 < 141, the quiet half stays
  EXPECT_EQ(field.stats().spatial_leaves, 2u + 7u);
  const GuidingField::Box quiet_box = field.leaf_box(quiet), busy_box = field.leaf_box(busy);
  EXPECT_EQ(quiet_box.lo, glm::vec3(0.0f, -1.0f, -1.0f));
  EXPECT_EQ(quiet_box.hi, glm::vec3(1.0f));
  const glm::vec3 busy_size = busy_box.hi - busy_box.lo;
  EXPECT_EQ(busy_size, glm::vec3(0.5f, 1.0f, 1.0f));  // x, then y, z, x again
  EXPECT_TRUE(glm::all(glm::lessThanEqual(busy_box.lo, busy)) && glm::all(glm::lessThan(busy, busy_box.hi)));
}

TEST(GuidingField, DifferentRegionsLearnDifferentLobes) {
  GuidingSettings settings;
  settings.spatial_threshold = 500.0f;
  GuidingField field(glm::vec3(-1.0f), glm::vec3(1.0f), settings);
  const Lighting up = cone_lighting(glm::vec3(0, 1, 0), 20.0f, 0.9f), down = cone_lighting(glm::vec3(0, -1, 0), 20.0f, 0.9f);
  // x < 0 sees the light above, x > 0 the one below.
  const auto split_lighting = [&](glm::vec3 p, glm::vec3 d) { return p.x < 0.0f ? up(d) : down(d); };
  for (int k = 0; k < 3; ++k) {
    Rng rng(3, 3, uint64_t(k));
    for (int i = 0; i < 20000; ++i) {
      const glm::vec3 p(2.0f * rng.next_float() - 1.0f, 2.0f * rng.next_float() - 1.0f, 2.0f * rng.next_float() - 1.0f);
      float pdf;
      const glm::vec3 d = field.sample(p, rng.next_2d(), &pdf);
      field.record(uint64_t(i), p, d, split_lighting(p, d), 1.0f / pdf);
    }
    field.end_iteration();
  }
  EXPECT_GT(field.stats().spatial_leaves, 2u);
  const glm::vec3 left(-0.5f, 0.1f, 0.2f), right(0.5f, 0.1f, 0.2f);
  EXPECT_GT(fraction_in_cone(field, left, up.lobes[0], 10000, 2), 0.7f);
  EXPECT_LT(fraction_in_cone(field, left, down.lobes[0], 10000, 2), 0.05f);
  EXPECT_GT(fraction_in_cone(field, right, down.lobes[0], 10000, 2), 0.7f);
  EXPECT_LT(fraction_in_cone(field, right, up.lobes[0], 10000, 2), 0.05f);
}

// Records independent of any field (uniform directions, weight 4 pi), with keys.
struct TestRecord {
  uint64_t key;
  glm::vec3 position, direction;
  float radiance, weight;
};
std::vector<TestRecord> make_records(int count, uint64_t seed) {
  const Lighting lighting = cone_lighting(glm::vec3(1, 1, 1), 10.0f, 0.8f);
  Rng rng(seed, 0, 0);
  std::vector<TestRecord> records;
  for (int i = 0; i < count; ++i) {
    TestRecord r;
    r.key = seed * 1000000 + uint64_t(i);
    r.position = glm::vec3(rng.next_float(), rng.next_float(), rng.next_float()) * 2.0f - 1.0f;
    r.direction = glm::vec3(rng.next_float(), rng.next_float(), rng.next_float()) * 2.0f - 1.0f;
    r.radiance = lighting(glm::normalize(r.direction)) * (1.0f + 0.1f * float(i % 7));
    r.weight = 4.0f * float(kPiD);
    records.push_back(r);
  }
  return records;
}

// Sources behind, at infinity and ahead (a focus) alike: the lobes' fits see every kind.
void record_one(GuidingField& field, const TestRecord& r) {
  field.record(r.key, r.position, r.direction, r.radiance, r.weight, 0.4f * float(int(r.key % 5) - 2));
}
void record_all(GuidingField& field, const std::vector<TestRecord>& records) {
  for (const TestRecord& r : records) record_one(field, r);
}

TEST(GuidingField, SameRecordsGiveTheSameFieldWhateverTheOrderAndThreads) {
 for (int lobes : {0, 8}) {  // the quadtrees, then the lobes' reservoirs and fits too
  SCOPED_TRACE(lobes);
  GuidingSettings settings;
  settings.spatial_threshold = 300.0f;
  settings.parallax_lobes = lobes;
  GuidingField in_order(glm::vec3(-1.0f), glm::vec3(1.0f), settings);
  GuidingField shuffled(glm::vec3(-1.0f), glm::vec3(1.0f), settings);
  GuidingField threaded(glm::vec3(-1.0f), glm::vec3(1.0f), settings);
  std::mt19937 shuffle(5);
  for (int iteration = 0; iteration < 3; ++iteration) {
    for (int frame = 0; frame < 2; ++frame) {  // apply_records() after each "frame", in all three
      const std::vector<TestRecord> records = make_records(8000, uint64_t(iteration * 2 + frame + 1));
      record_all(in_order, records);
      std::vector<TestRecord> mixed = records;
      std::shuffle(mixed.begin(), mixed.end(), shuffle);
      record_all(shuffled, mixed);
      std::vector<std::thread> threads;
      for (int t = 0; t < 4; ++t)
        threads.emplace_back([&, t] {
          for (size_t i = size_t(t); i < mixed.size(); i += 4)
            record_one(threaded, mixed[i]);
        });
      for (std::thread& thread : threads) thread.join();
      ASSERT_EQ(in_order.pending_records(), records.size());
      ASSERT_EQ(threaded.pending_records(), records.size());
      const std::vector<uint8_t> pending = in_order.serialize();  // buffered records included
      EXPECT_EQ(pending, shuffled.serialize());
      EXPECT_EQ(pending, threaded.serialize());
      in_order.apply_records();
      shuffled.apply_records();
      threaded.apply_records();
    }
    in_order.end_iteration();
    shuffled.end_iteration();
    threaded.end_iteration();
    const std::vector<uint8_t> bytes = in_order.serialize();
    EXPECT_EQ(bytes, shuffled.serialize()) << "iteration " << iteration;
    EXPECT_EQ(bytes, threaded.serialize()) << "iteration " << iteration;
  }
  EXPECT_GT(in_order.stats().spatial_leaves, 8u);
 }
}

TEST(GuidingField, MemoryBoundHoldsUnderAFloodOfRecords) {
  // The quadtrees alone, then with parallax lobes (whose reservoirs and lobes count at their most).
  const uint64_t with_lobes = GuidingField::kMinBytes + 8 * sizeof(GuidingLobe) + 128 * sizeof(GuidingLobeRecord);
  for (uint64_t bound : {GuidingField::kMinBytes, uint64_t(16) << 10, uint64_t(256) << 10, with_lobes, uint64_t(64) << 10,
                         uint64_t(512) << 10}) {
    SCOPED_TRACE(bound);
    const bool lobes = bound == with_lobes || bound == (uint64_t(64) << 10) || bound == (uint64_t(512) << 10);
    GuidingSettings settings;
    settings.spatial_threshold = 10.0f;
    settings.max_bytes = bound;
    settings.parallax_lobes = lobes ? 8 : 0;
    GuidingField field(glm::vec3(-1.0f), glm::vec3(1.0f), settings);
    EXPECT_LE(field.memory_bytes(), bound);
    std::mt19937 spiky(7);
    std::lognormal_distribution<float> radiance(0.0f, 3.0f);
    for (int iteration = 0; iteration < 5; ++iteration) {
      std::vector<TestRecord> records = make_records(30000, uint64_t(iteration + 1));
      for (TestRecord& r : records) r.radiance *= radiance(spiky);
      record_all(field, records);
      field.end_iteration();
      EXPECT_LE(field.memory_bytes(), bound) << "iteration " << iteration;
    }
    const GuidingField::Stats stats = field.stats();
    if (bound == GuidingField::kMinBytes || bound == with_lobes) {
      EXPECT_EQ(stats.spatial_leaves, 1u);
      EXPECT_EQ(stats.building_nodes, 1u);
    } else {
      EXPECT_GT(stats.spatial_leaves, 1u);
      EXPECT_GT(field.memory_bytes(), bound * 3 / 4) << "the bound, not the threshold, stopped the splits";
    }
    float pdf;
    field.sample(glm::vec3(0.1f), glm::vec2(0.3f, 0.7f), &pdf);
    EXPECT_TRUE(std::isfinite(pdf) && pdf > 0.0f);
  }
}

TEST(GuidingField, InvalidRecordsChangeNothing) {
  GuidingField clean(glm::vec3(-1.0f), glm::vec3(1.0f)), dirty(glm::vec3(-1.0f), glm::vec3(1.0f));
  const std::vector<TestRecord> records = make_records(5000, 3);
  for (int k = 0; k < 2; ++k) {
    record_all(clean, records);
    record_all(dirty, records);
    const glm::vec3 p(0.1f), d(0, 1, 0);
    for (float bad : {kNaN, kInf, -kInf, -1.0f}) {
      dirty.record(1, p, d, bad, 1.0f);
      dirty.record(2, p, d, 1.0f, bad);
      dirty.record(3, glm::vec3(bad == -1.0f ? kNaN : bad, 0.0f, 0.0f), d, 1.0f, 1.0f);
      if (bad != -1.0f) dirty.record(4, p, glm::vec3(bad, 1.0f, 0.0f), 1.0f, 1.0f);
    }
    dirty.record(5, p, glm::vec3(0.0f), 1.0f, 1.0f);
    dirty.record(6, p, glm::vec3(1e-30f, 0.0f, 0.0f) * 1e-20f, 1.0f, 1.0f);  // underflows to zero length
    EXPECT_EQ(clean.pending_records(), dirty.pending_records());
    clean.end_iteration();
    dirty.end_iteration();
    EXPECT_EQ(clean.serialize(), dirty.serialize());
  }
  // Queries out of range are answered with finite densities.
  for (glm::vec3 p : {glm::vec3(kNaN), glm::vec3(kInf, -kInf, 0.0f), glm::vec3(1e30f)})
    for (glm::vec2 u : {glm::vec2(kNaN), glm::vec2(1.0f), glm::vec2(-0.5f, 2.0f)}) {
      float pdf = -1.0f;
      const glm::vec3 d = dirty.sample(p, u, &pdf);
      EXPECT_NEAR(glm::length(d), 1.0f, 1e-6f);
      EXPECT_TRUE(std::isfinite(pdf) && pdf > 0.0f);
      EXPECT_EQ(pdf, dirty.pdf(p, d));
    }
  EXPECT_EQ(dirty.pdf(glm::vec3(0.0f), glm::vec3(0.0f)), 0.0f);
  EXPECT_EQ(dirty.pdf(glm::vec3(0.0f), glm::vec3(kNaN)), 0.0f);
}

TEST(GuidingField, RejectsBadSettings) {
  const auto make = [](GuidingSettings s, glm::vec3 lo = glm::vec3(0.0f), glm::vec3 hi = glm::vec3(1.0f)) {
    GuidingField field(lo, hi, s);
  };
  GuidingSettings s;
  EXPECT_NO_THROW(make(s));
  EXPECT_THROW(make(s, glm::vec3(1.0f), glm::vec3(0.0f)), std::runtime_error);
  EXPECT_THROW(make(s, glm::vec3(kNaN), glm::vec3(0.0f)), std::runtime_error);
  EXPECT_NO_THROW(make(s, glm::vec3(2.0f), glm::vec3(2.0f)));  // a point: a unit cube around it
  GuidingSettings bad = s;
  bad.max_bytes = GuidingField::kMinBytes - 1;
  EXPECT_THROW(make(bad), std::runtime_error);
  bad = s;
  bad.energy_threshold = 0.0f;
  EXPECT_THROW(make(bad), std::runtime_error);
  bad = s;
  bad.max_directional_depth = 21;
  EXPECT_THROW(make(bad), std::runtime_error);
  bad = s;
  bad.uniform_fraction = 0.0f;
  EXPECT_THROW(make(bad), std::runtime_error);
  bad = s;
  bad.spatial_threshold = kNaN;
  EXPECT_THROW(make(bad), std::runtime_error);
  bad = s;
  bad.delta_lobes = 1;  // delta lobes without lobes
  EXPECT_THROW(make(bad), std::runtime_error);
  bad.parallax_lobes = 4;
  EXPECT_NO_THROW(make(bad));
  bad.delta_lobes = 4;  // none left for the other light
  EXPECT_THROW(make(bad), std::runtime_error);
  bad.delta_lobes = -1;
  EXPECT_THROW(make(bad), std::runtime_error);
}

TEST(GuidingField, IterationsDoubleInLength) {
  std::vector<uint64_t> ends;
  for (uint64_t frames = 0; frames <= 64; ++frames)
    if (GuidingField::iteration_ends_after(frames)) ends.push_back(frames);
  EXPECT_EQ(ends, (std::vector<uint64_t>{1, 3, 7, 15, 31, 63}));  // iteration k: 2^k frames
}

// A trained field with several leaves and buffered records (and lobes, with `lobes` > 0).
GuidingField trained_field(int lobes = 0) {
  GuidingSettings settings;
  settings.spatial_threshold = 1000.0f;
  settings.parallax_lobes = lobes;
  GuidingField field(glm::vec3(-2.0f, -1.0f, 0.0f), glm::vec3(2.0f, 1.0f, 1.0f), settings);
  for (int k = 0; k < 3; ++k) {
    record_all(field, make_records(3000, uint64_t(k + 1)));
    field.end_iteration();
  }
  record_all(field, make_records(100, 9));
  return field;
}

TEST(GuidingField, SerializedFieldResumesExactly) {
  GuidingField field = trained_field();
  const std::vector<uint8_t> bytes = field.serialize();
  GuidingField restored = GuidingField::deserialize(bytes.data(), bytes.size());
  EXPECT_EQ(restored.serialize(), bytes);
  EXPECT_EQ(restored.iteration(), field.iteration());
  EXPECT_EQ(restored.pending_records(), 100u);
  Rng rng(4, 4, 4);
  for (int i = 0; i < 20000; ++i) {
    const glm::vec3 p = glm::vec3(rng.next_float(), rng.next_float(), rng.next_float()) * 4.0f - 2.0f;
    const glm::vec2 u = rng.next_2d();
    float pdf_a, pdf_b;
    const glm::vec3 a = field.sample(p, u, &pdf_a), b = restored.sample(p, u, &pdf_b);
    ASSERT_EQ(std::memcmp(&a, &b, sizeof a), 0);
    ASSERT_EQ(std::memcmp(&pdf_a, &pdf_b, sizeof pdf_a), 0);
    ASSERT_EQ(field.pdf(p, -a), restored.pdf(p, -a));
  }
  // Both go on the same way.
  const std::vector<TestRecord> more = make_records(2000, 10);
  record_all(field, more);
  record_all(restored, more);
  field.end_iteration();
  restored.end_iteration();
  EXPECT_EQ(field.serialize(), restored.serialize());
}

uint64_t test_fnv1a64(const uint8_t* data, size_t size) {
  uint64_t hash = 0xcbf29ce484222325ull;
  for (size_t i = 0; i < size; ++i) hash = (hash ^ data[i]) * 0x100000001b3ull;
  return hash;
}

// The checksum catches most damage; fixing it up afterwards (as a hostile file would) reaches the
// structural checks behind it.
void fix_checksum(std::vector<uint8_t>& bytes) {
  if (bytes.size() < 8) return;
  const uint64_t hash = test_fnv1a64(bytes.data(), bytes.size() - 8);
  std::memcpy(bytes.data() + bytes.size() - 8, &hash, 8);
}

TEST(GuidingField, CorruptBytesAreRejectedWithOneLine) {
 for (int lobes : {0, 8}) {
  SCOPED_TRACE(lobes);
  const GuidingField field = trained_field(lobes);
  const std::vector<uint8_t> good = field.serialize();
  const uint64_t bound = field.settings().max_bytes;
  int rejected = 0, accepted = 0;
  const auto attempt = [&](const std::vector<uint8_t>& bytes) {
    try {
      GuidingField f = GuidingField::deserialize(bytes.data(), bytes.size());
      ++accepted;
      // What is accepted is a usable field.
      float pdf = -1.0f;
      const glm::vec3 d = f.sample(glm::vec3(0.1f, 0.2f, 0.3f), glm::vec2(0.25f, 0.75f), &pdf);
      EXPECT_TRUE(std::isfinite(pdf) && pdf > 0.0f && std::isfinite(glm::length(d)));
      EXPECT_LE(f.memory_bytes(), f.settings().max_bytes);
      if (f.settings().max_bytes <= bound) {
        f.end_iteration();
        EXPECT_LE(f.memory_bytes(), f.settings().max_bytes);
      }
    } catch (const std::runtime_error& e) {
      ++rejected;
      const std::string message = e.what();
      EXPECT_FALSE(message.empty());
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
  };
  for (size_t length = 0; length < good.size(); length += 1 + length / 16) {
    std::vector<uint8_t> truncated(good.begin(), good.begin() + long(length));
    attempt(truncated);
    fix_checksum(truncated);
    attempt(truncated);
  }
  attempt(std::vector<uint8_t>(good.begin(), good.end() - 1));
  std::vector<uint8_t> longer = good;
  longer.insert(longer.end() - 8, 3, uint8_t(0));
  fix_checksum(longer);
  attempt(longer);
  std::mt19937 rng(12345);
  for (int trial = 0; trial < 3000; ++trial) {
    std::vector<uint8_t> bytes = good;
    const int mutations = 1 + int(rng() % 4);
    for (int m = 0; m < mutations; ++m) {
      const size_t at = rng() % bytes.size();
      switch (rng() % 4) {
        case 0: bytes[at] ^= uint8_t(1u << (rng() % 8)); break;
        case 1: bytes[at] = uint8_t(rng()); break;
        case 2: bytes.resize(at + 1); break;
        default: std::memset(bytes.data() + at, 0xff, std::min<size_t>(8, bytes.size() - at)); break;
      }
    }
    if (trial % 2) fix_checksum(bytes);
    attempt(bytes);
  }
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<uint8_t> garbage(rng() % 512);
    for (uint8_t& b : garbage) b = uint8_t(rng());
    attempt(garbage);
  }
  attempt(std::vector<uint8_t>());
  EXPECT_GT(rejected, 3000);
  EXPECT_GT(accepted, 0) << "mutated values with a fixed checksum: the checks of an accepted field ran";
  EXPECT_EQ(GuidingField::deserialize(good.data(), good.size()).serialize(), good);
 }
}

}  // namespace
}  // namespace pxf
