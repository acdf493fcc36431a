#include "pathtracer/guiding_lobes.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "pathtracer/guiding_field.h"
#include "pathtracer/rng.h"
#include "testing/stat_tests.h"

namespace pxf {
namespace {

constexpr double kPiD = 3.14159265358979323846;

// An orthonormal frame with `pole` as z, for bins around a narrow lobe.
struct Frame {
  glm::dvec3 x, y, z;
  explicit Frame(glm::dvec3 pole) : z(glm::normalize(pole)) {
    const glm::dvec3 a = std::abs(z.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
    x = glm::normalize(glm::cross(a, z));
    y = glm::cross(z, x);
  }
  glm::dvec3 to_world(double cos_theta, double phi) const {
    const double s = std::sqrt(std::max(0.0, 1.0 - cos_theta * cos_theta));
    return s * std::cos(phi) * x + s * std::sin(phi) * y + cos_theta * z;
  }
};

// Pearson's chi-square of a sampler against its pdf, in bins around `pole`: rows of 1 - cos theta
// spaced logarithmically from 1e-7 to 2 (so that lobes of any width from 0.03 degrees to the whole
// sphere fall in several rows), columns of phi. The expected counts integrate the pdf over each bin
// by the midpoint rule on a finer grid of the same coordinates.
template <class Pdf, class Sample>
stat::ChiSquareResult chi_square_around(glm::dvec3 pole, const Pdf& pdf, const Sample& sample, int samples,
                                        double* probability_sum) {
  constexpr int kRows = 40, kCols = 16, kSubRows = 64, kSubCols = 16;
  const double lo = std::log(1e-7), hi = std::log(2.0);
  const auto one_minus_cos_at = [&](double t) { return t <= 0.0 ? 0.0 : std::exp(lo + t * (hi - lo)); };
  const Frame frame(pole);
  std::vector<double> expected(kRows * kCols, 0.0), observed(kRows * kCols, 0.0);
  *probability_sum = 0.0;
  for (int r = 0; r < kRows; ++r)
    for (int sr = 0; sr < kSubRows; ++sr) {
      const double t0 = (r + double(sr) / kSubRows) / kRows, t1 = (r + double(sr + 1) / kSubRows) / kRows;
      const double a = r == 0 && sr == 0 ? 0.0 : one_minus_cos_at(t0), b = one_minus_cos_at(t1);
      const double cos_mid = 1.0 - 0.5 * (a + b);
      for (int c = 0; c < kCols; ++c)
        for (int sc = 0; sc < kSubCols; ++sc) {
          const double phi = 2.0 * kPiD * (c + (sc + 0.5) / kSubCols) / kCols;
          const double solid_angle = (b - a) * 2.0 * kPiD / (kCols * kSubCols);
          const double p = pdf(glm::vec3(frame.to_world(cos_mid, phi))) * solid_angle;
          expected[r * kCols + c] += p;
          *probability_sum += p;
        }
    }
  for (double& e : expected) e *= samples;
  Rng rng(17, 3, 5);
  for (int s = 0; s < samples; ++s) {
    const glm::dvec3 d = glm::normalize(glm::dvec3(sample(rng.next_2d())));
    const double one_minus_cos = std::max(1e-300, 1.0 - glm::dot(d, frame.z));
    const double t = (std::log(one_minus_cos) - lo) / (hi - lo);
    const int row = std::min(std::max(int(t * kRows), 0), kRows - 1);
    double phi = std::atan2(glm::dot(d, frame.y), glm::dot(d, frame.x));
    if (phi < 0.0) phi += 2.0 * kPiD;
    const int col = std::min(int(phi / (2.0 * kPiD) * kCols), kCols - 1);
    observed[row * kCols + col] += 1.0;
  }
  return stat::chi_square(observed, expected, 5.0);
}

TEST(GuidingLobes, VmfSamplesFollowItsPdf) {
  const glm::dvec3 mean = glm::normalize(glm::dvec3(0.3, -0.5, 0.8));
  for (double kappa : {0.05, 3.0, 200.0, 5.0e4}) {
    SCOPED_TRACE(kappa);
    double sum = 0.0;
    const stat::ChiSquareResult r = chi_square_around(
        mean, [&](glm::vec3 d) { return vmf_pdf(mean, kappa, glm::dvec3(d)); },
        [&](glm::vec2 u) { return vmf_sample(glm::vec3(mean), float(kappa), u); }, 200000, &sum);
    EXPECT_NEAR(sum, 1.0, 2e-3);
    EXPECT_TRUE(r.problem.empty()) << r.problem;
    EXPECT_GT(r.p_value, 0.01) << "chi2 " << r.statistic << " dof " << r.dof;
  }
}

std::vector<GuidingLobe> three_lobes() {
  std::vector<GuidingLobe> lobes(3);
  lobes[0].direction = glm::normalize(glm::vec3(1, 1, 0.2f));
  lobes[0].kappa = 3000.0f;
  lobes[0].share = 0.5f;
  lobes[0].source = glm::vec3(2.0f, 2.0f, 0.4f);  // at the direction's distance 2.87 from the origin
  lobes[0].distance = glm::length(lobes[0].source);
  lobes[1].direction = glm::vec3(0, 0, -1);
  lobes[1].kappa = 4.0f;
  lobes[1].share = 0.3f;
  lobes[2].direction = glm::normalize(glm::vec3(-1, 0.2f, 0.1f));
  lobes[2].kappa = 60.0f;
  lobes[2].share = 0.2f;
  return lobes;
}

TEST(GuidingLobes, MixtureSamplesFollowItsPdfAndRoundTrip) {
  const std::vector<GuidingLobe> lobes = three_lobes();
  const glm::vec3 point(0.3f, -0.2f, 0.1f);  // off the region's mean: the first lobe re-aims
  const LobeMixture mixture(lobes, point, 0.01f);
  const glm::dvec3 aimed = glm::normalize(glm::dvec3(lobes[0].source - point));
  for (glm::dvec3 pole : {aimed, glm::dvec3(0, 0, -1)}) {  // bins that resolve the narrow lobe, then the wide one
    double sum = 0.0;
    const stat::ChiSquareResult r = chi_square_around(
        pole, [&](glm::vec3 d) { return mixture.pdf(d); }, [&](glm::vec2 u) { return mixture.sample(u, nullptr); },
        300000, &sum);
    EXPECT_NEAR(sum, 1.0, 5e-3);
    EXPECT_TRUE(r.problem.empty()) << r.problem;
    EXPECT_GT(r.p_value, 0.01) << "chi2 " << r.statistic << " dof " << r.dof;
  }
  // sample()'s pdf is pdf() of its direction, and every pdf is positive and finite.
  Rng rng(3, 1, 1);
  for (int i = 0; i < 10000; ++i) {
    float p = -1.0f;
    const glm::vec3 d = mixture.sample(rng.next_2d(), &p);
    ASSERT_EQ(p, mixture.pdf(d));
    ASSERT_TRUE(p > 0.0f && std::isfinite(p));
    ASSERT_NEAR(glm::length(d), 1.0f, 1e-5f);
  }
  EXPECT_EQ(mixture.pdf(glm::vec3(0.0f)), 0.0f);
  EXPECT_EQ(mixture.pdf(glm::vec3(std::nanf(""), 0.0f, 1.0f)), 0.0f);
}

TEST(GuidingLobes, ALobeReaimsAtItsSourceAndNarrowsWithDistance) {
  std::vector<GuidingLobe> lobes(1);
  lobes[0].source = glm::vec3(0.0f, 0.0f, 2.0f);
  lobes[0].distance = 2.0f;
  lobes[0].direction = glm::vec3(0, 0, 1);
  lobes[0].kappa = 400.0f;
  lobes[0].share = 1.0f;
  for (glm::vec3 point : {glm::vec3(0.0f), glm::vec3(0.5f, 0.0f, 0.0f), glm::vec3(-0.3f, 0.4f, -2.0f)}) {
    const LobeMixture mixture(lobes, point, 0.01f);
    const glm::vec3 toward = glm::normalize(lobes[0].source - point);
    // The density peaks toward the source, and at twice the distance the lobe is about 4x as concentrated.
    EXPECT_GT(mixture.pdf(toward), mixture.pdf(glm::normalize(toward + glm::vec3(0.02f, 0.0f, 0.0f))));
    const float ratio = glm::length(lobes[0].source - point) / 2.0f;
    const double expected_peak = 0.99 * 400.0 * std::min(4.0f, std::max(0.25f, ratio * ratio)) / (2.0 * kPiD);
    EXPECT_NEAR(mixture.pdf(toward) / expected_peak, 1.0, 0.01) << point.x << " " << point.y << " " << point.z;
  }
  // Without a source (at infinity) the lobe keeps its direction everywhere.
  lobes[0].distance = 0.0f;
  const LobeMixture far(lobes, glm::vec3(5.0f, 0.0f, 0.0f), 0.01f);
  EXPECT_NEAR(far.pdf(glm::vec3(0, 0, 1)) * 2.0 * kPiD / 0.99, 400.0, 4.0);
}

TEST(GuidingLobes, LobesBehindTheSurfaceAreLeftOut) {
  std::vector<GuidingLobe> lobes(2);
  lobes[0].direction = glm::vec3(0, 0, 1);
  lobes[0].kappa = 100.0f;
  lobes[0].share = 0.5f;
  lobes[1].direction = glm::normalize(glm::vec3(1, 0, -0.3f));  // 17 degrees below a +z surface's horizon
  lobes[1].kappa = 100.0f;                                      // one standard deviation: about 6 degrees
  lobes[1].share = 0.5f;
  const LobeMixture both(lobes, glm::vec3(0.0f), 0.01f), above(lobes, glm::vec3(0.0f), 0.01f, glm::vec3(0, 0, 1));
  EXPECT_NEAR(both.pdf(lobes[1].direction), 0.99 * 0.5 * 100.0 / (2.0 * kPiD), 0.1);
  EXPECT_NEAR(above.pdf(lobes[1].direction), 0.01 / (4.0 * kPiD) + 0.99 * 100.0 / (2.0 * kPiD) * std::exp(-100.0 * (1.0 - glm::dot(lobes[0].direction, lobes[1].direction))), 1e-6);
  EXPECT_NEAR(above.pdf(glm::vec3(0, 0, 1)), 0.99 * 100.0 / (2.0 * kPiD), 0.1);  // the lobe above takes all the share
  lobes[1].kappa = 4.0f;  // wide: half a radian, so 17 degrees below is within reach and it stays
  EXPECT_GT(LobeMixture(lobes, glm::vec3(0.0f), 0.01f, glm::vec3(0, 0, 1)).pdf(lobes[1].direction), 0.1);
  EXPECT_TRUE(LobeMixture({lobes[0]}, glm::vec3(0.0f), 0.01f, glm::vec3(0, 0, -1)).empty());
  EXPECT_FLOAT_EQ(LobeMixture(lobes, glm::vec3(0.0f), 0.01f).share(), 1.0f);
  // Lobes wider than min_kappa are left out too, and share() says what is left.
  const LobeMixture narrow(lobes, glm::vec3(0.0f), 0.01f, glm::vec3(0.0f), 10.0f);
  EXPECT_FLOAT_EQ(narrow.share(), 0.5f);
  EXPECT_NEAR(narrow.pdf(glm::vec3(0, 0, 1)), 0.99 * 100.0 / (2.0 * kPiD), 0.1);
  EXPECT_FLOAT_EQ(LobeMixture(lobes, glm::vec3(0.0f), 0.01f, glm::vec3(0.0f), 200.0f).share(), 0.0f);
}

// Photons from a small sphere of light (radius 0.05 around `light`) arriving at points spread over
// a region: each record's source is its point on the light.
std::vector<GuidingLobeRecord> photons_from(glm::vec3 light, glm::vec3 region_lo, glm::vec3 region_hi, int count,
                                            uint64_t seed) {
  Rng rng(seed, 2, 3);
  std::vector<GuidingLobeRecord> records;
  for (int i = 0; i < count; ++i) {
    GuidingLobeRecord r;
    r.key = seed * 100000 + uint64_t(i);
    r.position = region_lo + (region_hi - region_lo) * glm::vec3(rng.next_float(), rng.next_float(), rng.next_float());
    glm::vec3 offset;
    do offset = glm::vec3(rng.next_float(), rng.next_float(), rng.next_float()) * 2.0f - 1.0f;
    while (glm::length(offset) > 1.0f);
    r.source = light + 0.05f * offset;
    r.priority = lobe_record_priority(r.key, 1.0f);
    records.push_back(r);
  }
  return records;
}

TEST(GuidingLobes, FitFindsTheSourcesOfTwoLights) {
  // A region 0.4 wide, lit by two small lights 1 and 3 away in different directions, 3:1 in photons.
  const glm::vec3 lo(-0.2f), hi(0.2f), near_light(0.0f, 0.0f, 1.0f), far_light(3.0f, 0.0f, 0.0f);
  std::vector<GuidingLobeRecord> records = photons_from(near_light, lo, hi, 300, 1);
  const std::vector<GuidingLobeRecord> more = photons_from(far_light, lo, hi, 100, 2);
  records.insert(records.end(), more.begin(), more.end());
  const std::vector<GuidingLobe> lobes = fit_guiding_lobes(records, 8);
  ASSERT_FALSE(lobes.empty());
  double near_share = 0.0, far_share = 0.0, total = 0.0;
  for (const GuidingLobe& lobe : lobes) {
    total += lobe.share;
    ASSERT_GT(lobe.distance, 0.0f);
    EXPECT_NEAR(lobe.distance, glm::length(lobe.source), 0.05f);  // from the records' mean position, about 0
    if (glm::length(lobe.source - near_light) < 0.05f) near_share += lobe.share;
    if (glm::length(lobe.source - far_light) < 0.05f) far_share += lobe.share;
  }
  EXPECT_NEAR(total, 1.0, 1e-5);
  EXPECT_NEAR(near_share, 0.75, 0.03);
  EXPECT_NEAR(far_share, 0.25, 0.03);
  // From a corner of the region, most guided samples head for the lights' spheres (which cover
  // about 0.4 % of the directions together): the lobes aim at the lights, not in the directions
  // the lights had from the region's centre.
  for (glm::vec3 corner : {lo, hi, glm::vec3(0.2f, -0.2f, 0.2f)}) {
    const LobeMixture mixture(lobes, corner, 0.01f);
    Rng rng(9, 9, 9);
    int hits = 0;
    constexpr int kSamples = 20000;
    for (int i = 0; i < kSamples; ++i) {
      const glm::vec3 d = mixture.sample(rng.next_2d(), nullptr);
      for (glm::vec3 light : {near_light, far_light}) {
        const glm::vec3 to = light - corner;
        const float along = glm::dot(to, d);
        if (along > 0.0f && glm::length(to - along * d) < 0.07f) {
          ++hits;
          break;
        }
      }
    }
    EXPECT_GT(double(hits) / kSamples, 0.7) << corner.x << " " << corner.y << " " << corner.z;
  }
}

TEST(GuidingLobes, GuidedShareFollowsHowWellTheLobesFitTheRecords) {
  // Records of a small light above a floor region (normal +z), and lobes fitted to other records of it.
  const glm::vec3 light(0.0f, 0.0f, 1.0f), lo(-0.2f, -0.2f, 0.0f), hi(0.2f, 0.2f, 0.0f);
  std::vector<GuidingLobeRecord> fit = photons_from(light, lo, hi, 200, 21), judge = photons_from(light, lo, hi, 200, 22);
  for (GuidingLobeRecord& r : judge) r.normal = glm::vec3(0, 0, 1);
  const std::vector<GuidingLobe> good = fit_guiding_lobes(fit, 8);
  EXPECT_GE(best_guided_share(good, judge, 0.01f, 10.0f, 0.5f), 0.8f);
  // Lobes aimed 60 degrees off the light (above the horizon, so not left out): no guiding pays.
  std::vector<GuidingLobe> wrong = good;
  for (GuidingLobe& lobe : wrong) {
    lobe.distance = 0.0f;
    lobe.direction = glm::normalize(glm::vec3(std::sqrt(3.0f), 0.0f, 1.0f));
  }
  EXPECT_EQ(best_guided_share(wrong, judge, 0.01f, 10.0f, 0.5f), 0.0f);
  // Half the light from the small light, half from the whole sky: somewhere between.
  std::vector<GuidingLobeRecord> mixed = judge;
  Rng rng(8, 8, 8);
  for (GuidingLobeRecord& r : mixed)
    if (r.key % 2) {
      const glm::vec2 u = rng.next_2d();
      const float z = std::sqrt(u.x), s = std::sqrt(1.0f - u.x);  // cosine-distributed: L_i cos of a uniform sky
      r.source = glm::vec3(s * std::cos(6.2831853f * u.y), s * std::sin(6.2831853f * u.y), z);
      r.kind = kSourceAtInfinity;
    }
  const float between = best_guided_share(good, mixed, 0.01f, 10.0f, 0.5f);
  EXPECT_GT(between, 0.0f);
  EXPECT_LT(between, best_guided_share(good, judge, 0.01f, 10.0f, 0.5f));
  // Weights say how much light each record stands for: a scale changes nothing, and weighing up
  // the small light's records (or the sky's) moves the share toward theirs.
  std::vector<double> same(mixed.size(), 0.25), light_heavy(mixed.size()), sky_heavy(mixed.size());
  for (size_t i = 0; i < mixed.size(); ++i) {
    light_heavy[i] = mixed[i].key % 2 ? 0.1 : 1.0;
    sky_heavy[i] = mixed[i].key % 2 ? 1.0 : 0.1;
  }
  EXPECT_EQ(best_guided_share(good, mixed, 0.01f, 10.0f, 0.5f, same), between);
  EXPECT_GT(best_guided_share(good, mixed, 0.01f, 10.0f, 0.5f, light_heavy), between);
  EXPECT_LT(best_guided_share(good, mixed, 0.01f, 10.0f, 0.5f, sky_heavy), between);
  // Records without a normal cannot judge: the fallback stays.
  EXPECT_EQ(best_guided_share(good, fit, 0.01f, 10.0f, 0.3f), 0.3f);
}

TEST(GuidingLobes, ReservoirKeepsTheSameRecordsWhateverTheOrder) {
  std::vector<GuidingLobeRecord> records = photons_from(glm::vec3(0, 0, 1), glm::vec3(-1.0f), glm::vec3(1.0f), 2000, 4);
  for (size_t i = 0; i < records.size(); ++i) records[i].priority = lobe_record_priority(records[i].key, 1.0f + float(i % 5));
  std::vector<GuidingLobeRecord> a, b;
  for (size_t start = 0; start < records.size(); start += 300)
    merge_into_reservoir(a, {records.begin() + long(start), records.begin() + long(std::min(start + 300, records.size()))}, 128);
  std::vector<GuidingLobeRecord> shuffled = records;
  std::shuffle(shuffled.begin(), shuffled.end(), std::mt19937(3));
  for (size_t start = 0; start < shuffled.size(); start += 77)
    merge_into_reservoir(b, {shuffled.begin() + long(start), shuffled.begin() + long(std::min(start + 77, shuffled.size()))}, 128);
  ASSERT_EQ(a.size(), 128u);
  ASSERT_LE(a.capacity(), 128u);
  const auto keys = [](std::vector<GuidingLobeRecord> v) {
    std::vector<uint64_t> k;
    for (const GuidingLobeRecord& r : v) k.push_back(r.key);
    std::sort(k.begin(), k.end());
    return k;
  };
  EXPECT_EQ(keys(a), keys(b));
  // Heavier records are kept more often: the energy-5 records (a fifth of them) hold more than a fifth.
  int heavy = 0;
  for (const GuidingLobeRecord& r : a) heavy += (r.key % 100000) % 5 == 4;
  EXPECT_GT(heavy, 128 / 5 + 10);
}

TEST(GuidingLobes, AFocusNearerThanItsLeafIsKeptAsADirection) {
  // Records over a patch of one leaf (the box's diagonal 3.46), their light arriving straight down
  // (from +y) from a point `distance` along it: behind the record (> 0) or a focus ahead (< 0). A
  // focus within the leaf's size moves with the receiving point, so the field keeps only the
  // direction; a farther focus and a source behind keep their points.
  const auto largest_lobe = [](float distance) {
    GuidingSettings settings;
    settings.spatial_threshold = 1e9f;  // one leaf
    settings.parallax_lobes = 8;
    GuidingField field(glm::vec3(-1.0f), glm::vec3(1.0f), settings);
    Rng rng(3, 4, 5);
    for (uint64_t k = 0; k < 400; ++k) {
      const glm::vec2 u = rng.next_2d();
      const glm::vec3 position(0.6f * u.x - 0.3f, -0.5f, 0.6f * u.y - 0.3f);
      field.record(k, position, glm::vec3(0.0f, 1.0f, 0.0f), 1.0f, 1.0f, distance, glm::vec3(0.0f, 1.0f, 0.0f));
    }
    field.end_iteration();
    const std::vector<GuidingLobe>& lobes = field.lobes(glm::vec3(0.0f, -0.5f, 0.0f));
    EXPECT_FALSE(lobes.empty());
    return lobes.empty() ? GuidingLobe{} : *std::max_element(lobes.begin(), lobes.end(), [](const GuidingLobe& a, const GuidingLobe& b) {
      return a.share < b.share;
    });
  };
  const GuidingLobe near_focus = largest_lobe(-0.2f);
  EXPECT_EQ(near_focus.distance, 0.0f);
  EXPECT_GT(glm::dot(near_focus.direction, glm::vec3(0.0f, 1.0f, 0.0f)), 0.999f);
  EXPECT_GT(near_focus.kappa, 1000.0f);  // one direction for the whole patch
  EXPECT_LT(largest_lobe(-5.0f).distance, 0.0f);   // a focus beyond the leaf: still a point
  EXPECT_GT(largest_lobe(0.2f).distance, 0.0f);    // a near source behind: still a point
}

// A field with records applied but its iteration not ended serializes, restores to the same bytes,
// and ends the iteration exactly as the original does: lobes and reservoirs included.
void expect_restores_exactly(GuidingField& pending) {
  const std::vector<uint8_t> bytes = pending.serialize();
  GuidingField restored = GuidingField::deserialize(bytes.data(), bytes.size());
  EXPECT_EQ(restored.serialize(), bytes);
  pending.end_iteration();
  restored.end_iteration();
  EXPECT_EQ(restored.serialize(), pending.serialize());
}

TEST(GuidingLobes, FieldWithLobesGuidesEveryPointOfALeafToTheLight) {
  // One leaf (a high split threshold) lit by a small light: the field's lobes aim at the light from
  // every point; its quadtree, learned from the same records, spreads over the directions the light
  // has from the leaf's points.
  const glm::vec3 light(0.0f, 0.0f, 0.9f);
  const auto train = [&](int lobes) {
    GuidingSettings settings;
    settings.spatial_threshold = 1e9f;
    settings.parallax_lobes = lobes;
    GuidingField field(glm::vec3(-1.0f), glm::vec3(1.0f), settings);
    const std::vector<GuidingLobeRecord> photons = photons_from(light, glm::vec3(-0.8f, -0.8f, -0.8f), glm::vec3(0.8f, 0.8f, 0.0f), 4000, 7);
    for (int k = 0; k < 2; ++k) {
      for (const GuidingLobeRecord& p : photons)
        field.record(p.key + uint64_t(k) * 1000000, p.position, p.source - p.position, 1.0f, 1.0f, glm::length(p.source - p.position));
      field.end_iteration();
    }
    return field;
  };
  const GuidingField with_lobes = train(8), quadtree = train(0);
  EXPECT_EQ(with_lobes.stats().spatial_leaves, 1u);
  const auto hit_fraction = [&](const GuidingField& field, glm::vec3 point) {
    Rng rng(5, 5, 5);
    int hits = 0;
    for (int i = 0; i < 20000; ++i) {
      float pdf;
      const glm::vec3 d = field.sample(point, rng.next_2d(), &pdf);
      EXPECT_EQ(pdf, field.pdf(point, d));
      const glm::vec3 to = light - point;
      const float along = glm::dot(to, d);
      hits += along > 0.0f && glm::length(to - along * d) < 0.06f;
    }
    return hits / 20000.0;
  };
  for (glm::vec3 point : {glm::vec3(-0.7f, -0.7f, -0.7f), glm::vec3(0.6f, -0.2f, -0.1f), glm::vec3(0.0f, 0.7f, -0.4f)}) {
    const double lobes = hit_fraction(with_lobes, point), tree = hit_fraction(quadtree, point);
    EXPECT_GT(lobes, 0.6) << point.x << " " << point.y << " " << point.z;
    EXPECT_GT(lobes, 3.0 * tree) << "quadtree " << tree;
  }
  // And it serializes and restores exactly, lobes and reservoir included.
  GuidingField pending = train(8);
  pending.record(42, glm::vec3(0.1f), glm::vec3(0, 0, 1), 1.0f, 1.0f, 0.5f);
  pending.apply_records();
  expect_restores_exactly(pending);
}

// A leaf lit by sixteen lights, and by one more, 1 % of its energy, through a mirror: in one
// reservoir that light's few records join a neighbour's lobe, so guiding barely aims at it (the
// mirror caustic on a Cornell box wall, docs/guiding.md). With delta lobes its records have a
// reservoir of their own, and it gets lobes of its own, weighted by its share of the energy.
TEST(GuidingLobes, LightThroughDeltaBouncesGetsLobesOfItsOwn) {
  // Sixteen lights on a ring take the leaf's lobes; the mirrored one sits between two of them.
  const float between = float(kPiD) / 16.0f;
  const glm::vec3 lo(-0.8f, -0.8f, -0.8f), hi(0.8f, 0.8f, 0.0f),
      mirrored(1.6f * std::cos(between), 1.6f * std::sin(between), 0.8f);
  const auto train = [&](int delta_lobes) {
    GuidingSettings settings;
    settings.spatial_threshold = 1e9f;
    settings.parallax_lobes = 8;
    settings.delta_lobes = delta_lobes;
    GuidingField field(glm::vec3(-3.0f), glm::vec3(3.0f), settings);
    for (int light = 0; light < 16; ++light) {
      const float angle = float(kPiD) * 2.0f * float(light) / 16.0f;
      const glm::vec3 at(1.6f * std::cos(angle), 1.6f * std::sin(angle), 0.8f);
      for (const GuidingLobeRecord& p : photons_from(at, lo, hi, 250, 10 + uint64_t(light)))
        field.record(p.key, p.position, p.source - p.position, 1.0f, 1.0f, glm::length(p.source - p.position));
    }
    for (const GuidingLobeRecord& p : photons_from(mirrored, lo, hi, 40, 30))
      field.record(p.key, p.position, p.source - p.position, 1.0f, 1.0f, glm::length(p.source - p.position),
                   glm::vec3(0.0f), true);
    field.end_iteration();
    return field;
  };
  const GuidingField one_reservoir = train(0), own_reservoir = train(4);
  EXPECT_EQ(own_reservoir.stats().spatial_leaves, 1u);
  for (glm::vec3 point : {glm::vec3(-0.6f, -0.6f, -0.6f), glm::vec3(0.5f, -0.1f, -0.2f), glm::vec3(0.0f, 0.6f, -0.1f)}) {
    const glm::vec3 toward = glm::normalize(mirrored - point);
    const float with = own_reservoir.pdf(point, toward), without = one_reservoir.pdf(point, toward);
    // Its own reservoir concentrates a lobe on the mirrored light: several times the density.
    EXPECT_GT(with, 5.0f * without) << point.x << " " << point.y << " " << point.z;
    EXPECT_GT(with, 5.0f);
  }
  // The delta reservoir serializes and restores exactly.
  GuidingField pending = train(4);
  pending.record(43, glm::vec3(0.1f), glm::vec3(0, 0, 1), 1.0f, 1.0f, 0.5f, glm::vec3(0.0f), true);
  pending.record(44, glm::vec3(0.1f), glm::vec3(0, 1, 1), 1.0f, 1.0f, 0.5f);
  pending.apply_records();
  expect_restores_exactly(pending);
}

}  // namespace
}  // namespace pxf
