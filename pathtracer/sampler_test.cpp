// The Sobol sampler: the generator matrices against known points, the (0,m,2)-net property of the
// 2D pairs before and after Owen scrambling and shuffling, a chi-square test of uniformity of the
// scrambled points, per-pixel decorrelation, and the replicate variance estimate.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "pathtracer/integrator.h"
#include "pathtracer/sampler.h"
#include "testing/stat_tests.h"

namespace pxf {
namespace {

// Every elementary interval of area 2^-m (2^a x 2^(m-a) cells, all a) holds exactly one point.
bool is_02_net(const std::vector<glm::uvec2>& bits, int m, std::string* problem) {
  for (int a = 0; a <= m; ++a) {
    std::vector<int> count(size_t(1) << m, 0);
    for (const glm::uvec2& p : bits) {
      const uint32_t cx = a == 0 ? 0 : p.x >> (32 - a), cy = (m - a) == 0 ? 0 : p.y >> (32 - (m - a));
      ++count[(cy << a) | cx];
    }
    for (size_t c = 0; c < count.size(); ++c)
      if (count[c] != 1) {
        *problem = "m=" + std::to_string(m) + " a=" + std::to_string(a) + " cell " + std::to_string(c) + " holds " +
                   std::to_string(count[c]);
        return false;
      }
  }
  return true;
}

TEST(Sobol, MatricesGiveTheKnownFirstPoints) {
  // Sobol points 0..7 in dimensions 1..4 (Joe-Kuo), from their reference generator.
  const float expected[8][4] = {{0, 0, 0, 0},
                                {0.5f, 0.5f, 0.5f, 0.5f},
                                {0.75f, 0.25f, 0.25f, 0.25f},
                                {0.25f, 0.75f, 0.75f, 0.75f},
                                {0.375f, 0.375f, 0.625f, 0.875f},
                                {0.875f, 0.875f, 0.125f, 0.375f},
                                {0.625f, 0.125f, 0.875f, 0.625f},
                                {0.125f, 0.625f, 0.375f, 0.125f}};
  // The reference generator skips nothing but orders by Gray code; the matrices here index in
  // binary order, so point i here is Gray-code point g(i) = i ^ (i >> 1) there.
  for (uint32_t i = 0; i < 8; ++i) {
    const uint32_t gray_rank = i;  // find j with j ^ (j >> 1) == i
    uint32_t j = 0;
    while ((j ^ (j >> 1)) != gray_rank) ++j;
    for (int d = 0; d < sobol::kDimensions; ++d)
      EXPECT_FLOAT_EQ(sobol::to_unit_float(sobol::sample_bits(i, d)), expected[j][d]) << "point " << i << " dim " << d;
  }
}

TEST(Sobol, FastPathEqualsTheNestedScrambleDefinition) {
  // The byte tables in the bit-reversed domain against the plain loop over index bits, and the
  // sampler's scrambled coordinate against Burley's definition written out.
  Rng rng(5, 0, 0);
  for (int i = 0; i < 2000; ++i) {
    const uint32_t index = rng.next_u32(), seed = rng.next_u32();
    const uint64_t key = (static_cast<uint64_t>(rng.next_u32()) << 32) | seed;
    for (int d = 0; d < sobol::kDimensions; ++d) {
      ASSERT_EQ(sobol::reversed_sample_bits(sobol::reverse_bits(index), d), sobol::reverse_bits(sobol::sample_bits(index, d)));
      const uint32_t shuffled = sobol::nested_uniform_scramble(index, seed);
      const uint32_t dim_seed = sobol::dimension_seed(static_cast<uint32_t>(key >> 32), d);
      ASSERT_EQ(sobol::scrambled_bits(index, d, key),
                sobol::nested_uniform_scramble(sobol::sample_bits(shuffled, d), dim_seed));
      const sobol::ScrambledGroup g(sobol::reverse_bits(index), key);
      ASSERT_EQ(g.unit(d), sobol::to_unit_float(g.bits(d)));  // the byte-table reversal to float
    }
  }
}

TEST(Sobol, PairsAreZeroTwoNetsBeforeAndAfterScrambling) {
  for (int m = 1; m <= 10; ++m) {
    const uint32_t n = 1u << m;
    std::vector<glm::uvec2> plain, scrambled;
    for (uint32_t i = 0; i < n; ++i) {
      plain.emplace_back(sobol::sample_bits(i, 0), sobol::sample_bits(i, 1));
      // Shuffled index and Owen-scrambled coordinates, as the sampler draws them.
      const uint64_t key = 0x1234567ULL + m;
      scrambled.emplace_back(sobol::scrambled_bits(i, 0, key), sobol::scrambled_bits(i, 1, key));
    }
    std::string problem;
    EXPECT_TRUE(is_02_net(plain, m, &problem)) << "unscrambled: " << problem;
    EXPECT_TRUE(is_02_net(scrambled, m, &problem)) << "scrambled: " << problem;
  }
}

TEST(Sobol, NetCheckCatchesAPointOutOfPlace) {
  std::vector<glm::uvec2> points;
  for (uint32_t i = 0; i < 16; ++i) points.emplace_back(sobol::sample_bits(i, 0), sobol::sample_bits(i, 1));
  points[5] = points[6];
  std::string problem;
  EXPECT_FALSE(is_02_net(points, 4, &problem));
}

TEST(Sobol, SamplerPairsOfEveryGroupStratifyAcrossFrames) {
  // The 2D dimensions the integrator uses (camera jitter, light point, BSDF direction of several
  // vertices), for one pixel over frames 0 .. 2^m - 1 of one replicate.
  const int m = 8;
  for (int group = 0; group < 5; ++group) {
    std::vector<glm::uvec2> points;
    for (uint32_t frame = 0; frame < (1u << m); ++frame) {
      PathSampler sampler(SamplerType::Sobol, 7, 1234, frame, 1);
      glm::vec2 u = group == 0   ? sampler.camera_jitter()
                    : group % 2 ? sampler.light_numbers(2 + group / 2, true).point
                                : sampler.bsdf_numbers(2 + group / 2, false, false).direction;
      points.emplace_back(static_cast<uint32_t>(u.x * 0x1p32f), static_cast<uint32_t>(u.y * 0x1p32f));
    }
    std::string problem;
    EXPECT_TRUE(is_02_net(points, m, &problem)) << "group " << group << ": " << problem;
  }
}

TEST(Sobol, ScrambledPointsAreUniformAcrossPixels) {
  // One point per pixel (frame 5, the same index everywhere): only the per-pixel scramble varies,
  // so the points must be i.i.d. uniform. Chi-square on a 16 x 16 grid of each 2D pair and on 64
  // bins of each 1D dimension.
  const int pixels = 25600, grid = 16, bins = 64;
  std::vector<double> cam(grid * grid, 0), light(grid * grid, 0), dir(grid * grid, 0);
  std::vector<double> lobe(bins, 0), roulette(bins, 0), specular(bins, 0);
  auto cell = [&](glm::vec2 u) { return static_cast<int>(u.y * grid) * grid + static_cast<int>(u.x * grid); };
  for (int p = 0; p < pixels; ++p) {
    PathSampler s(SamplerType::Sobol, 3, static_cast<uint64_t>(p), 5, 4);
    ++cam[cell(s.camera_jitter())];
    ++light[cell(s.light_numbers(3, true).point)];
    const PathSampler::BsdfNumbers b = s.bsdf_numbers(3, true, true);
    ++dir[cell(b.direction)];
    ++lobe[static_cast<int>(b.lobe * bins)];
    ++roulette[static_cast<int>(b.roulette * bins)];
    ++specular[static_cast<int>(s.specular_numbers(3).select * bins)];
  }
  auto check = [&](const std::vector<double>& observed, const char* name) {
    std::vector<double> expected(observed.size(), static_cast<double>(pixels) / observed.size());
    stat::ChiSquareResult r = stat::chi_square(observed, expected);
    EXPECT_GT(r.p_value, 1e-4) << name << " chi2 " << r.statistic << " dof " << r.dof;
  };
  check(cam, "camera");
  check(light, "light point");
  check(dir, "bsdf direction");
  check(lobe, "bsdf lobe");
  check(roulette, "roulette");
  check(specular, "specular object");
}

TEST(Sobol, NeighbouringPixelsAndGroupsAreUncorrelated) {
  // Pearson correlation over many frames between pixel p and p + 1, and between the light and the
  // BSDF pair of one vertex: |r| within 4 standard errors of 0.
  const int n = 4096;
  double sxy = 0, sx = 0, sy = 0, sxx = 0, syy = 0, gxy = 0, gx = 0, gy = 0, gxx = 0, gyy = 0;
  for (int f = 0; f < n; ++f) {
    PathSampler a(SamplerType::Sobol, 1, 100, static_cast<uint32_t>(f), 1), b(SamplerType::Sobol, 1, 101, static_cast<uint32_t>(f), 1);
    double x = a.camera_jitter().x, y = b.camera_jitter().x;
    sxy += x * y, sx += x, sy += y, sxx += x * x, syy += y * y;
    double l = a.light_numbers(2, true).point.x, d = a.bsdf_numbers(2, false, false).direction.x;
    gxy += l * d, gx += l, gy += d, gxx += l * l, gyy += d * d;
  }
  auto corr = [n](double xy, double x, double y, double xx, double yy) {
    return (xy / n - x / n * y / n) / std::sqrt((xx / n - x / n * x / n) * (yy / n - y / n * y / n));
  };
  EXPECT_LT(std::abs(corr(sxy, sx, sy, sxx, syy)), 4.0 / std::sqrt(n));
  EXPECT_LT(std::abs(corr(gxy, gx, gy, gxx, gyy)), 4.0 / std::sqrt(n));
}

TEST(Sobol, IndependentSamplerKeepsTheOldStreams) {
  // The independent sampler is the pre-Sobol integrator: jitter from Rng(seed, pixel, frame), the
  // path from a second stream, drawn in call order.
  PathSampler s(SamplerType::Independent, 9, 77, 3, 4);
  Rng pixel(9, 77, 3), path(9 ^ 0x5bd1e9955bd1e995ULL, 77, 3);
  EXPECT_EQ(s.camera_jitter(), pixel.next_2d());
  // Every number is drawn, used or not, in the old order: light selection, light point, BSDF
  // lobe, direction, roulette.
  const PathSampler::LightNumbers light = s.light_numbers(2, false);
  EXPECT_FALSE(light.shared);
  EXPECT_EQ(light.select, path.next_float());
  EXPECT_EQ(light.point, path.next_2d());
  const PathSampler::BsdfNumbers bsdf = s.bsdf_numbers(2, false, false);
  EXPECT_EQ(bsdf.lobe, path.next_float());
  EXPECT_EQ(bsdf.direction, path.next_2d());
  EXPECT_EQ(bsdf.roulette, path.next_float());
}

TEST(Sobol, VertexNumbersAreTheNumbersTheVertexWouldDraw) {
  // The batch loop takes a vertex's Sobol numbers from vertex_numbers() before shading; they must
  // be the ones light_numbers() and bsdf_numbers() give, bit for bit, on every vertex, pixel,
  // frame and replicate count, with and without roulette.
  for (int replicates : {1, 4})
    for (uint32_t frame : {0u, 1u, 7u, 100u, 4097u})
      for (uint64_t pixel : {0ull, 5ull, 123457ull})
        for (int vertex : {2, 3, 6})
          for (bool roulette : {false, true}) {
            const PathSampler sampler(SamplerType::Sobol, 11, pixel, frame, replicates);
            const PathSampler::VertexNumbers n = sampler.vertex_numbers(vertex, roulette);
            PathSampler drawn = sampler;
            const PathSampler::LightNumbers light = drawn.light_numbers(vertex, true);
            const PathSampler::BsdfNumbers bsdf = drawn.bsdf_numbers(vertex, true, roulette);
            const std::string where = "frame " + std::to_string(frame) + " pixel " + std::to_string(pixel) +
                                      " vertex " + std::to_string(vertex);
            EXPECT_EQ(n.light.point, light.point) << where;
            EXPECT_EQ(n.light.shared, light.shared) << where;
            EXPECT_EQ(n.bsdf.direction, bsdf.direction) << where;
            EXPECT_EQ(n.bsdf.lobe, bsdf.lobe) << where;
            EXPECT_EQ(n.bsdf.roulette, bsdf.roulette) << where;
          }
}

TEST(Sobol, PathTailAfterLeavingQmcIsFreshEveryFrame) {
  // After leave_qmc() a path draws PCG32 numbers. The Sobol key holds the replicate, not the
  // frame, so the tail stream must take the frame in: over the frames of one pixel and replicate
  // the tail's numbers are i.i.d. uniform (chi-square, 64 bins) and never repeat a frame's.
  const int frames = 8192, bins = 64;
  std::vector<double> observed(bins, 0);
  std::vector<float> first;
  for (uint32_t f = 0; f < frames; ++f) {
    PathSampler s(SamplerType::Sobol, 4, 321, f, 1);
    s.leave_qmc();
    EXPECT_FALSE(s.in_qmc());
    const float u = s.bsdf_numbers(3, true, true).direction.x;
    ++observed[static_cast<int>(u * bins)];
    first.push_back(u);
  }
  std::vector<double> expected(bins, static_cast<double>(frames) / bins);
  const stat::ChiSquareResult r = stat::chi_square(observed, expected);
  EXPECT_GT(r.p_value, 1e-4) << "chi2 " << r.statistic << " dof " << r.dof;
  // 24-bit values: about frames^2 / 2^25 = 2 equal pairs by chance; a repeating tail gives thousands.
  std::sort(first.begin(), first.end());
  int equal = 0;
  for (size_t i = 1; i < first.size(); ++i) equal += first[i] == first[i - 1];
  EXPECT_LT(equal, 16) << "the tails of different frames repeat";
}

TEST(Accumulation, ReplicateVarianceFromReplicateMeans) {
  Accumulation acc;
  resize_accumulation(acc, 1, 1, 2);
  EXPECT_EQ(acc.replicate_variance_of_mean(0), -1.0f);
  // Replicate 0: 1, 3 (mean 2); replicate 1: 5, 7 (mean 6). Overall mean 4; estimate
  // 2/1 * ((1/2)^2 * 4 + (1/2)^2 * 4) = 4.
  for (float y : {1.0f, 5.0f, 3.0f, 7.0f}) accumulate_sample(acc, 0, glm::vec3(0), glm::vec3(y), acc.samples[0]);
  EXPECT_NEAR(acc.replicate_variance_of_mean(0), 4.0f, 1e-5f);
  // One pixel: the pooled gain is its own, so the estimate is the replicate one.
  EXPECT_NEAR(acc.variance_of_mean(0), 4.0f, 1e-5f);
  // s^2 / n = (20/3) / 4.
  EXPECT_NEAR(acc.per_sample_variance_of_mean(0), 20.0f / 12.0f, 1e-5f);
}

TEST(Accumulation, VarianceImageEqualsPerPixelQueries) {
  // 5 x 4 pixels, 4 replicates, per-pixel noise of different scales: the whole-image estimate is
  // bit-identical to the per-pixel one, and differs from s^2 / n where the replicates disagree.
  Accumulation acc;
  resize_accumulation(acc, 5, 4, 4);
  Rng rng(12, 0, 0);
  for (int frame = 0; frame < 11; ++frame)
    for (size_t p = 0; p < 20; ++p)
      accumulate_sample(acc, p, glm::vec3(0), glm::vec3(rng.next_float() * (1.0f + p) + (frame % 4 == 1 ? 0.5f : 0.0f)),
                        frame % 4);
  const std::vector<float> image = acc.variance_of_mean_image();
  int differs = 0;
  for (size_t p = 0; p < 20; ++p) {
    EXPECT_EQ(image[p], acc.variance_of_mean(p)) << p;
    EXPECT_GT(image[p], 0.0f);
    differs += std::abs(image[p] - acc.per_sample_variance_of_mean(p)) > 1e-3f * image[p];
  }
  EXPECT_GT(differs, 10);
}

}  // namespace
}  // namespace pxf
