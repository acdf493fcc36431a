// Filter, blend and tone-map shaders against the CPU reference (gl/cpu_reference.h) on small
// random images with edges in range color and depth.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include "gl/blend_pass.h"
#include "gl/cpu_reference.h"
#include "gl/demodulation.h"
#include "gl/filter_pass.h"
#include "gl/inputs.h"
#include "gl/test_util.h"
#include "gl/tonemap_pass.h"

namespace pxf {
namespace {

constexpr int W = 37, H = 29;
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

struct Scenario {
  Image lv = Image::rgb(W, H), hv = Image::rgb(W, H), var = Image::gray(W, H);
  Image range = Image::rgb(W, H), depth = Image::gray(W, H);
  Image surface = Image::rgba(W, H);  // xyz shading normal (0: unknown), w roughness
};

// The surface buffer of a scenario: three normal regions split vertically (across the color and
// depth regions), a few shortened normals as at antialiased edges, a few unknown ones, and two
// roughness bands. Its own random stream, so the other buffers are those of make_scenario alone.
void fill_surface(Scenario& s, unsigned seed) {
  std::mt19937 rng(seed ^ 0x5eedu);
  std::uniform_real_distribution<float> u01(0.0f, 1.0f);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      glm::vec3 n = x < W / 3 ? glm::vec3(0, 0, 1) : x < 2 * W / 3 ? glm::vec3(0.5f, 0, 1) : glm::vec3(0, -0.6f, 1);
      n = glm::normalize(n + 0.1f * glm::vec3(u01(rng), u01(rng), u01(rng)));
      const float r = u01(rng);
      if (r < 0.1f) n *= 0.6f;                   // a mixed edge pixel
      if (r > 0.96f) n = glm::vec3(0.0f);        // unknown
      for (int c = 0; c < 3; ++c) s.surface.at(x, y, c) = n[c];
      s.surface.at(x, y, 3) = (y % 7 < 3 ? 0.2f : 0.6f) + 0.05f * u01(rng);
    }
}

// Two range-color regions split by a diagonal, two depth regions split horizontally, noisy HV
// with known, unknown (n < 2) and zero (all samples equal) variance, a few L_b = 0 pixels.
Scenario make_scenario(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u01(0.0f, 1.0f);
  Scenario s;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      bool left = x + y / 2 < W / 2, top = y < H / 2;
      float base[3] = {left ? 0.5f : 0.1f, left ? 0.2f : 0.4f, left ? 0.1f : 0.6f};
      for (int c = 0; c < 3; ++c) {
        s.range.at(x, y, c) = base[c] + 0.02f * u01(rng);
        s.hv.at(x, y, c) = (top ? 2.0f : 0.5f) * base[c] * (0.2f + 1.6f * u01(rng));
        s.lv.at(x, y, c) = 0.3f * u01(rng);
      }
      s.depth.at(x, y, 0) = (top ? 2.0f : 5.0f) + 0.3f * u01(rng);
      float r = u01(rng);
      s.var.at(x, y, 0) = r < 0.05f ? kVarUnknown : 0.002f * std::pow(10.0f, 3.0f * u01(rng));
      if (r > 0.93f) s.var.at(x, y, 0) = 0.0f;  // all samples equal (n >= 2): not trusted
      if (r > 0.97f)  // all samples black: L_b = 0 unless the filter brings light
        for (int c = 0; c < 3; ++c) s.hv.at(x, y, c) = s.lv.at(x, y, c) = 0.0f;
    }
  fill_surface(s, seed);
  return s;
}

Image guide_image(const Scenario& s) {
  Image g = Image::rgba(W, H);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      for (int c = 0; c < 3; ++c) g.at(x, y, c) = s.range.at(x, y, c);
      g.at(x, y, 3) = s.depth.at(x, y, 0);
    }
  return g;
}

void expect_close(const Image& gpu, const Image& cpu, float rel, float abs, const char* what) {
  ASSERT_EQ(gpu.pixels.size(), cpu.pixels.size());
  size_t bad = 0;
  for (size_t i = 0; i < gpu.pixels.size(); ++i) {
    float a = gpu.pixels[i], b = cpu.pixels[i];
    ASSERT_TRUE(std::isfinite(a)) << what << " sample " << i;
    if (std::abs(a - b) > rel * std::max(std::abs(a), std::abs(b)) + abs && bad++ < 5) {
      ADD_FAILURE() << what << " sample " << i << ": gpu " << a << " cpu " << b;
    }
  }
  EXPECT_EQ(bad, 0u) << what;
}

struct GpuFixture {
  PreviewInputs inputs{W, H};
  Texture2D guide{W, H, TextureFormat::RGBA32F};
  Texture2D surface{W, H, TextureFormat::RGBA32F};
  explicit GpuFixture(const Scenario& s) {
    inputs.upload(s.lv, s.hv, s.var);
    guide.upload(guide_image(s));
    surface.upload(s.surface);
  }
};

// A CPU filter output as the texture the blend reads: rgb L_f, a Var[L_f] (or a sentinel).
Texture2D filtered_texture(const FilterOutput& f) {
  Image packed = Image::rgba(f.filtered.width, f.filtered.height);
  for (size_t i = 0; i < packed.pixel_count(); ++i) {
    for (int c = 0; c < 3; ++c) packed.pixels[4 * i + c] = f.filtered.pixels[3 * i + c];
    packed.pixels[4 * i + 3] = f.variance.pixels[i];
  }
  Texture2D texture(packed.width, packed.height, TextureFormat::RGBA32F);
  texture.upload(packed);
  return texture;
}

// The blend pass on the GPU against the CPU reference's output `cpu` for the same inputs.
void expect_gpu_blend_matches(const Scenario& s, const FilterOutput& f, float t, const BlendParams& params,
                              const BlendOutput& cpu) {
  GpuFixture gpu(s);
  const Texture2D filtered = filtered_texture(f);
  BlendPass blend(W, H);
  blend.run(gpu.inputs, &filtered, &gpu.guide, t, params);
  expect_close(blend.s_image(), cpu.s, 1e-4f, 1e-5f, "s");
  expect_close(blend.case_image(), cpu.blend_case, 0.0f, 0.0f, "case");
}

class FilterVsCpu : public ::testing::TestWithParam<std::tuple<FilterKind, bool, float>> {};

TEST_P(FilterVsCpu, MatchesReference) {
  test::osmesa_context();
  auto [kind, skip, sigma_s] = GetParam();
  Scenario s = make_scenario(7);
  GpuFixture gpu(s);
  FilterParams p;
  p.kind = kind;
  p.skip_case2 = skip;
  p.sigma_s = sigma_s;
  const float t = 0.05f;
  // Without the surface buffer (its terms off), then with it (normal and roughness terms on).
  for (bool with_surface : {false, true}) {
  SCOPED_TRACE(with_surface ? "with surface" : "without surface");
  FilterPass filter(W, H);
  filter.run(gpu.inputs, gpu.guide, p, t, with_surface ? &gpu.surface : nullptr);
  FilterOutput ref = cpu_filter(s.hv, s.var, s.lv, s.range, s.depth, p, t, with_surface ? &s.surface : nullptr);
  expect_close(filter.filtered_image(), ref.filtered, 1e-4f, 1e-7f, "L_f");
  expect_close(filter.raw_variance_image(), ref.variance, 1e-4f, 1e-12f, "Var[L_f]");
  // The centre weight for the blend's covariance term: the full-kernel variants only.
  ASSERT_EQ(filter.centre_weight() != nullptr, !ref.centre_weight.pixels.empty());
  if (filter.centre_weight()) {
    expect_close(filter.centre_weight_image(), ref.centre_weight, 1e-4f, 1e-7f, "centre weight");
  }
  size_t skipped = 0;
  for (float v : ref.variance.pixels) skipped += v == kVarSkipped;
  if (skip) {
    EXPECT_GT(skipped, 0u);
  }
  EXPECT_EQ(filter.filtered_pixels(), W * H - skipped);
  }
}

INSTANTIATE_TEST_SUITE_P(Variants, FilterVsCpu,
                         ::testing::Values(std::make_tuple(FilterKind::BilateralDepth, false, 8.0f),
                                           std::make_tuple(FilterKind::BilateralDepth, true, 8.0f),
                                           std::make_tuple(FilterKind::Bilateral, false, 8.0f),
                                           std::make_tuple(FilterKind::Bilateral, true, 2.5f),
                                           std::make_tuple(FilterKind::BilateralDepth, false, 0.0f),
                                           std::make_tuple(FilterKind::Separable, false, 8.0f),
                                           std::make_tuple(FilterKind::Separable, true, 3.0f),
                                           std::make_tuple(FilterKind::Atrous, false, 8.0f),
                                           std::make_tuple(FilterKind::Atrous, true, 8.0f),
                                           std::make_tuple(FilterKind::Atrous, true, 2.5f),
                                           std::make_tuple(FilterKind::Atrous, false, 0.0f),
                                           std::make_tuple(FilterKind::Atrous, false, 21.0f),
                                           std::make_tuple(FilterKind::Subsampled, false, 8.0f),
                                           std::make_tuple(FilterKind::Subsampled, true, 8.0f),
                                           std::make_tuple(FilterKind::Subsampled, true, 2.5f),
                                           std::make_tuple(FilterKind::Subsampled, false, 0.0f),
                                           std::make_tuple(FilterKind::Subsampled, false, 21.0f),
                                           std::make_tuple(FilterKind::Grid, false, 8.0f),
                                           std::make_tuple(FilterKind::Grid, true, 8.0f),
                                           std::make_tuple(FilterKind::Grid, false, 0.0f),
                                           std::make_tuple(FilterKind::Grid, true, 21.0f)));

TEST(FilterKinds, ConstantHvStaysConstant) {
  // The weights are normalized, so a constant signal comes out unchanged whatever the range edges.
  test::osmesa_context();
  Scenario s = make_scenario(13);
  for (float& v : s.hv.pixels) v = 0.7f;
  GpuFixture gpu(s);
  FilterPass filter(W, H);
  for (const std::string& name : filter_kind_names()) {
    FilterParams p;
    p.kind = parse_filter_kind(name);
    p.skip_case2 = false;
    filter.run(gpu.inputs, gpu.guide, p, test::kTestThreshold);
    Image f = filter.filtered_image();
    size_t off = 0;
    for (float v : f.pixels) off += std::abs(v - 0.7f) > 1e-5f;
    EXPECT_EQ(off, 0u) << name;
  }
}

// prepare() sets a variant up ahead of its first run (FilterPass::prepare) and changes nothing in
// what the run computes: a prepared pass and a fresh one give the same L_f bit for bit.
TEST(FilterKinds, APreparedPassFiltersAsAFreshOne) {
  test::osmesa_context();
  Scenario s = make_scenario(17);
  GpuFixture gpu(s);
  for (const std::string& name : filter_kind_names()) {
    FilterParams p;
    p.kind = parse_filter_kind(name);
    FilterPass fresh(W, H), prepared(W, H);
    prepared.prepare(p.kind);
    if (p.kind == FilterKind::Grid) EXPECT_NE(prepared.grid(), nullptr);  // made before the run
    prepared.prepare(p.kind);  // a second call keeps what the first set up
    fresh.run(gpu.inputs, gpu.guide, p, test::kTestThreshold);
    prepared.run(gpu.inputs, gpu.guide, p, test::kTestThreshold);
    EXPECT_EQ(prepared.raw_variance_image().pixels, fresh.raw_variance_image().pixels) << name;
    EXPECT_EQ(prepared.filtered_image().pixels, fresh.filtered_image().pixels) << name;
  }
}

TEST(Atrous, IterationsFollowSigmaS) {
  // k passes have B3 variance (4^k - 1) / 3: 1, 5, 21, 85, 341; the first that reaches sigma_s^2,
  // at least 1, at most 5 (footprint radius 62 <= kMaxFilterRadius).
  EXPECT_EQ(atrous_iterations(0.0f), 1);
  EXPECT_EQ(atrous_iterations(1.0f), 1);
  EXPECT_EQ(atrous_iterations(1.5f), 2);
  EXPECT_EQ(atrous_iterations(4.5f), 3);
  EXPECT_EQ(atrous_iterations(4.6f), 4);
  EXPECT_EQ(atrous_iterations(8.0f), 4);
  EXPECT_EQ(atrous_iterations(kMaxFilterRadius / 3.0f), 5);
  EXPECT_EQ(atrous_iterations(kInf), 5);
  EXPECT_EQ(atrous_iterations(kNaN), 1);
}

// A step in range color, and one in depth, with constant HV on each side: no mixing across.
void expect_edges_preserved(FilterKind kind) {
  test::osmesa_context();
  Scenario s = make_scenario(3);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      bool left = x < W / 2, top = y < H / 2;
      for (int c = 0; c < 3; ++c) {
        s.range.at(x, y, c) = left ? 0.8f : 0.1f;
        s.hv.at(x, y, c) = (left ? 1.0f : 3.0f) * (top ? 1.0f : 2.0f);
      }
      s.depth.at(x, y, 0) = top ? 3.0f : 30.0f;
      s.var.at(x, y, 0) = 0.5f;
    }
  GpuFixture gpu(s);
  FilterPass filter(W, H);
  FilterParams p;
  p.kind = kind;
  p.skip_case2 = false;
  filter.run(gpu.inputs, gpu.guide, p, test::kTestThreshold);
  Image f = filter.filtered_image();
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x)
      EXPECT_NEAR(f.at(x, y, 0), (x < W / 2 ? 1.0f : 3.0f) * (y < H / 2 ? 1.0f : 2.0f), 1e-5f);
}

TEST(Atrous, EdgesArePreserved) { expect_edges_preserved(FilterKind::Atrous); }

TEST(Atrous, ZeroVarianceIsNoEvidence) {
  // Var[L_u] = 0 with n >= 2 (identical samples) is no evidence of low variance: as a neighbour it
  // counts like kVarUnknown; the pixel itself is skipped only on its neighbours' (pooled) evidence,
  // never when no neighbour variance is known.
  test::osmesa_context();
  Scenario s = make_scenario(17);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x)
      if ((x + 3 * y) % 7 == 0) s.var.at(x, y, 0) = 0.0f;
  GpuFixture gpu(s);
  FilterPass filter(W, H);
  FilterParams p;
  p.kind = FilterKind::Atrous;
  const float t = 0.05f;
  for (bool skip : {false, true}) {
    p.skip_case2 = skip;
    filter.run(gpu.inputs, gpu.guide, p, t);
    FilterOutput ref = cpu_filter(s.hv, s.var, s.lv, s.range, s.depth, p, t);
    expect_close(filter.filtered_image(), ref.filtered, 1e-4f, 1e-7f, "L_f");
    expect_close(filter.raw_variance_image(), ref.variance, 1e-4f, 1e-12f, "Var[L_f]");
  }
  // Only zero variances: nothing is known, nothing is skipped.
  for (float& v : s.var.pixels) v = 0.0f;
  GpuFixture zeros(s);
  filter.run(zeros.inputs, zeros.guide, p, t);
  EXPECT_EQ(filter.filtered_pixels(), uint32_t(W * H));
  for (float v : filter.raw_variance_image().pixels) EXPECT_EQ(v, kVarUnknown);
}

// The composite 1D kernel of `passes` à-trous passes on a flat guide: the B3 taps at spacing
// 1, 2, 4, ... convolved with each other.
std::vector<double> composite_b3_kernel(int passes) {
  std::vector<double> kernel = {1.0};
  for (int i = 0; i < passes; ++i) {
    const int step = 1 << i;
    const double b3[5] = {1 / 16.0, 4 / 16.0, 6 / 16.0, 4 / 16.0, 1 / 16.0};
    std::vector<double> next(kernel.size() + 4 * step, 0.0);
    for (size_t k = 0; k < kernel.size(); ++k)
      for (int j = 0; j < 5; ++j) next[k + j * step] += kernel[k] * b3[j];
    kernel = next;
  }
  return kernel;
}

// White noise, uniform in [0, 2] (mean 1, variance 1/3), filtered over a flat guide: there a filter
// is a fixed linear kernel, so what it does to the noise's variance is known, and the Var[L_f] it
// claims can be checked against it. One realization per run().
class WhiteNoiseOnFlatGuide {
 public:
  static constexpr float kNoiseVar = 1.0f / 3.0f;
  WhiteNoiseOnFlatGuide(int n, unsigned seed)
      : context_(test::osmesa_context()),
        n_(n),
        lv_(Image::rgb(n, n)),
        var_(Image::gray(n, n, "Y", kNoiseVar)),
        inputs_(n, n),
        guide_(n, n, TextureFormat::RGBA32F),
        filter_(n, n),
        rng_(seed) {
    guide_.upload(Image::rgba(n, n, 0.5f));
  }
  const FilterPass& run(const FilterParams& p) {
    Image hv = Image::rgb(n_, n_);
    for (float& v : hv.pixels) v = noise_(rng_);
    inputs_.upload(lv_, hv, var_);
    filter_.run(inputs_, guide_, p, test::kTestThreshold);
    return filter_;
  }
  const FilterPass& filter() const { return filter_; }  // as the last run() left it

 private:
  GlContext& context_;  // first: the GL objects below need it current
  int n_;
  Image lv_, var_;
  PreviewInputs inputs_;
  Texture2D guide_;
  FilterPass filter_;
  std::mt19937 rng_;
  std::uniform_real_distribution<float> noise_{0.0f, 2.0f};
};

// The background skip (kBackgroundOnlyDistance): a third of the image is sky in the guide (distance
// kBackgroundDepth). The filter leaves those pixels as they are (kVarSkipped: the blend shows L_u),
// and the surface pixels come out the same whatever the sky's pixels hold, as the distance term
// gives the sky no weight. GPU against CPU.
TEST(Atrous, LeavesTheBackgroundAsItIsAndTheSurfaceWithoutIt) {
  test::osmesa_context();
  FilterParams p;
  p.kind = FilterKind::Atrous;
  p.skip_case2 = false;
  const float t = 0.05f;
  auto with_sky = [](float sky_hv) {
    Scenario s = make_scenario(11);
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W / 3; ++x) {
        s.depth.at(x, y, 0) = kBackgroundDepth;
        for (int c = 0; c < 3; ++c) s.hv.at(x, y, c) = sky_hv * float(1 + (x + y) % 3);
      }
    return s;
  };
  const Scenario dark = with_sky(0.0f), lit = with_sky(5.0f);
  const FilterOutput a = cpu_filter(dark.hv, dark.var, dark.lv, dark.range, dark.depth, p, t);
  const FilterOutput b = cpu_filter(lit.hv, lit.var, lit.lv, lit.range, lit.depth, p, t);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x)
      for (int c = 0; c < 3; ++c) {
        if (x < W / 3) {
          ASSERT_EQ(b.filtered.at(x, y, c), lit.hv.at(x, y, c)) << x << "," << y;
          ASSERT_EQ(b.variance.at(x, y, 0), kVarSkipped) << x << "," << y;
        } else {
          ASSERT_EQ(a.filtered.at(x, y, c), b.filtered.at(x, y, c)) << x << "," << y;
        }
      }
  GpuFixture gpu(lit);
  FilterPass filter(W, H);
  filter.run(gpu.inputs, gpu.guide, p, t);
  expect_close(filter.filtered_image(), b.filtered, 1e-4f, 1e-7f, "L_f");
  expect_close(filter.raw_variance_image(), b.variance, 1e-4f, 1e-12f, "Var[L_f]");
}

TEST(Atrous, WhiteNoiseVarianceShrinksBySumOfSquaredWeights) {
  // On a flat guide the à-trous filter is a fixed linear kernel W (the composite of the passes),
  // so white noise of variance v comes out with variance v sum W^2 = v (sum_i c_i^2)^2 (c: the
  // composite 1D kernel). One pass: W = h and the propagated Var[L_f] = v sum h^2 is exact. More
  // passes: each pass's inputs are correlated; without atrous_variance_correction the propagated
  // Var[L_f] would be (sum h^2)^passes, 28.8x too low at sigma_s = 8. With it, it is exact here.
  constexpr int N = 192;
  constexpr float kNoiseVar = WhiteNoiseOnFlatGuide::kNoiseVar;
  WhiteNoiseOnFlatGuide rig(N, 5);
  for (float sigma_s : {1.0f, 8.0f}) {
    FilterParams p;
    p.kind = FilterKind::Atrous;
    p.sigma_s = sigma_s;
    p.sigma_l = 0.0f;  // a fixed linear kernel: the luminance edge stop depends on the noise
    p.skip_case2 = false;
    const int passes = atrous_iterations(sigma_s);
    const int margin = 2 * ((1 << passes) - 1);  // the footprint radius: no border effects inside
    double sum_c2 = 0;
    for (double c : composite_b3_kernel(passes)) sum_c2 += c * c;
    const double expected = sum_c2 * sum_c2;
    double sum_sq = 0;
    size_t count = 0;
    for (int realization = 0; realization < 12; ++realization) {
      const Image f = rig.run(p).filtered_image();
      for (int y = margin; y < N - margin; ++y)
        for (int x = margin; x < N - margin; ++x, ++count) sum_sq += (f.at(x, y, 0) - 1.0) * (f.at(x, y, 0) - 1.0);
    }
    const double measured = sum_sq / count / kNoiseVar;
    const double propagated = rig.filter().raw_variance_image().at(N / 2, N / 2, 0) / kNoiseVar;
    const double per_pass = std::pow(70.0 / 256.0, 2);  // sum h^2 of the 5x5 kernel: (sum b3^2)^2
    const double uncorrected = std::pow(per_pass, passes);
    std::printf("sigma_s %g, %d passes: white-noise variance x %.3g measured, x %.3g expected (sum W^2), "
                "Var[L_f] x %.3g (uncorrected x %.3g)\n",
                sigma_s, passes, measured, expected, propagated, uncorrected);
    EXPECT_NEAR(measured / expected, 1.0, 0.15) << sigma_s;
    EXPECT_NEAR(propagated / expected, 1.0, 1e-3) << sigma_s;
    if (passes > 1) {
      EXPECT_GT(expected / uncorrected, 20.0) << "the correction matters";
    }
  }
}

TEST(Subsampled, TapTableFollowsTheSpatialGaussian) {
  // Every rotation holds kSubsampledTaps taps in all (counts), the centre among them, within the
  // exact kernel's radius 3 sigma_s; their mean squared distance is that of the Gaussian truncated
  // at 3 sigma_s, 2 sigma_s^2 (1 - 4.5 e^-4.5 / (1 - e^-4.5)) = 1.90 sigma_s^2, apart from the
  // centre; and the rotations differ.
  const float sigma = 8.0f;
  const SubsampledTapTable table = subsampled_tap_table(sigma, kSubsampledTaps);
  ASSERT_EQ(table.taps.size(), size_t(table.per_rotation) * kSubsampledRotations);
  double r2_sum = 0;
  int r2_count = 0, differing = 0;
  for (int r = 0; r < kSubsampledRotations; ++r) {
    int total = 0, centre = 0;
    for (int i = 0; i < table.per_rotation; ++i) {
      const SubsampledTap& tap = table.taps[size_t(r) * table.per_rotation + i];
      total += tap.count;
      if (tap.count == 0) continue;
      EXPECT_LE(tap.dx * tap.dx + tap.dy * tap.dy, std::pow(3 * sigma + 1, 2));
      if (tap.dx == 0 && tap.dy == 0) {
        centre = tap.count;
        continue;
      }
      r2_sum += tap.count * double(tap.dx * tap.dx + tap.dy * tap.dy);
      r2_count += tap.count;
      if (r > 0 && (tap.dx != table.taps[i].dx || tap.dy != table.taps[i].dy)) ++differing;
    }
    EXPECT_EQ(total, kSubsampledTaps) << r;
    EXPECT_GE(centre, 1) << r;
  }
  EXPECT_NEAR(r2_sum / r2_count / (sigma * sigma), 1.90, 0.3);
  EXPECT_GT(differing, 0);
  // No spatial extent: the centre alone, every tap merged into it.
  const SubsampledTapTable none = subsampled_tap_table(0.0f, kSubsampledTaps);
  EXPECT_EQ(none.per_rotation, 1);
  EXPECT_EQ(none.taps[0].count, kSubsampledTaps);
  EXPECT_EQ(subsampled_tap_table(kNaN, 5).taps[0].count, 5);
}

TEST(Subsampled, RotationsCoverTheTableEvenly) {
  std::vector<int> hits(kSubsampledRotations, 0);
  for (int y = 0; y < 256; ++y)
    for (int x = 0; x < 256; ++x) ++hits[subsampled_rotation(x, y)];
  const double expected = 256.0 * 256.0 / kSubsampledRotations;
  for (int h : hits) EXPECT_NEAR(h, expected, 5 * std::sqrt(expected));
}

TEST(Subsampled, WhiteNoiseVarianceIsExactForTheWeightsUsed) {
  // On a flat guide each pixel's output is a fixed linear combination of its taps (count-weighted),
  // so white noise of variance v comes out with variance v sum c^2 / (sum c)^2 per pixel, which is
  // the propagated Var[L_f] if duplicates are merged (a tap counted twice contributes 4 v, not 2 v).
  // Checked as the mean of (L_f - 1)^2 / Var[L_f] over pixels and realizations, which must be 1.
  constexpr int N = 96;
  constexpr float kNoiseVar = WhiteNoiseOnFlatGuide::kNoiseVar;
  WhiteNoiseOnFlatGuide rig(N, 11);
  for (float sigma_s : {1.5f, 8.0f}) {
    FilterParams p;
    p.kind = FilterKind::Subsampled;
    p.sigma_s = sigma_s;
    p.skip_case2 = false;
    double ratio_sum = 0, independent_sum = 0;
    size_t count = 0;
    for (int realization = 0; realization < 12; ++realization) {
      const FilterPass& filter = rig.run(p);
      const Image f = filter.filtered_image(), vf = filter.raw_variance_image();
      const SubsampledTapTable table = subsampled_tap_table(sigma_s, kSubsampledTaps);
      for (int y = 0; y < N; ++y)
        for (int x = 0; x < N; ++x, ++count) {
          ASSERT_GT(vf.at(x, y, 0), 0.0f);
          const double e2 = (f.at(x, y, 0) - 1.0) * (f.at(x, y, 0) - 1.0);
          ratio_sum += e2 / vf.at(x, y, 0);
          // What unmerged duplicates would claim: v sum over taps of 1 / (sum taps)^2 = v / n_in.
          double n_in = 0;
          const SubsampledTap* taps = &table.taps[size_t(subsampled_rotation(x, y)) * table.per_rotation];
          for (int i = 0; i < table.per_rotation; ++i) {
            const int qx = x + taps[i].dx, qy = y + taps[i].dy;
            if (qx >= 0 && qx < N && qy >= 0 && qy < N) n_in += taps[i].count;
          }
          independent_sum += e2 / (kNoiseVar / n_in);
        }
    }
    const double ratio = ratio_sum / count, independent = independent_sum / count;
    std::printf("sigma_s %g: measured / propagated Var[L_f] = %.3f; / (v / taps) = %.3f\n", sigma_s, ratio, independent);
    EXPECT_NEAR(ratio, 1.0, 0.05) << sigma_s;
    if (sigma_s < 2.0f) {
      EXPECT_GT(independent, 1.3) << "duplicates merged matter at small sigma_s";
    }
  }
}

TEST(Subsampled, EdgesArePreserved) { expect_edges_preserved(FilterKind::Subsampled); }

TEST(FilterVsCpu, EdgesArePreserved) {
  // A step in range color with constant HV on each side: the filter must not mix the sides.
  test::osmesa_context();
  Scenario s = make_scenario(3);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      bool left = x < W / 2;
      for (int c = 0; c < 3; ++c) {
        s.range.at(x, y, c) = left ? 0.8f : 0.1f;
        s.hv.at(x, y, c) = left ? 1.0f : 3.0f;
      }
      s.depth.at(x, y, 0) = 3.0f;
      s.var.at(x, y, 0) = 0.5f;
    }
  GpuFixture gpu(s);
  FilterPass filter(W, H);
  FilterParams p;
  p.skip_case2 = false;
  filter.run(gpu.inputs, gpu.guide, p, test::kTestThreshold);
  Image f = filter.filtered_image();
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) EXPECT_NEAR(f.at(x, y, 0), x < W / 2 ? 1.0f : 3.0f, 1e-5f);
}

TEST(BlendVsCpu, MatchesReferenceWithFilteredInput) {
  test::osmesa_context();
  Scenario s = make_scenario(11);
  // Non-finite and extreme inputs must come out finite.
  s.hv.at(1, 1, 0) = kNaN;
  s.hv.at(2, 1, 1) = kInf;
  s.lv.at(3, 1, 2) = -kInf;
  s.var.at(4, 1, 0) = kNaN;
  s.var.at(5, 1, 0) = 1e30f;
  s.var.at(6, 1, 0) = 1e-30f;
  s.hv.at(7, 1, 0) = 1e30f;
  GpuFixture gpu(s);
  for (bool skip : {false, true}) {
    FilterParams fp;
    fp.skip_case2 = skip;
    const float filter_t = 0.02f;
    FilterOutput ref_f = cpu_filter(s.hv, s.var, s.lv, s.range, s.depth, fp, filter_t);
    ref_f.centre_weight = Image();  // the blend below gets L_f as a plain texture, without a centre weight
    const Texture2D filtered = filtered_texture(ref_f);
    for (float t : {0.0f, 0.001f, 0.02f, 0.2f})
      for (int pool : {0, 1, 2})  // 2: pooling with the surface terms
        for (bool guard : {false, true}) {
      SCOPED_TRACE(testing::Message() << "t=" << t << " pool=" << pool << " skip=" << skip << " guard=" << guard);
      BlendPass blend(W, H);
      const BlendParams bp{range_weights(fp), guard};
      blend.run(gpu.inputs, &filtered, pool ? &gpu.guide : nullptr, t, bp, nullptr, pool == 2 ? &gpu.surface : nullptr);
      BlendOutput ref = cpu_blend(s.lv, s.hv, s.var, &ref_f, t, bp, pool ? &s.range : nullptr, pool ? &s.depth : nullptr,
                                  pool == 2 ? &s.surface : nullptr);
      expect_close(blend.final_image(), ref.final_rgb, 1e-4f, 1e-6f, "final");
      expect_close(blend.s_image(), ref.s, 1e-4f, 1e-5f, "s");
      expect_close(blend.case_image(), ref.blend_case, 0.0f, 0.0f, "case");
      auto counts = blend.case_counts();
      uint32_t total = 0;
      for (int c = 0; c < kBlendCaseCount; ++c) {
        uint32_t expected = 0;
        for (float v : ref.blend_case.pixels) expected += static_cast<int>(v) == c;
        EXPECT_EQ(counts[c], expected) << "case " << c;
        total += counts[c];
      }
      EXPECT_EQ(total, uint32_t(W * H));
      // Where the blend mixes, this filter's L_f is biased enough somewhere (the scenario's HV
      // steps at its region borders) for the guard to act.
      if (guard && t > 0.0f && t < 0.2f) {
        EXPECT_GT(counts[kCaseBiasGuard], 0u);
      }
      if (!guard) {
        EXPECT_EQ(counts[kCaseBiasGuard], 0u);
      }
    }
  }
}

// The halves of a scenario's pixels (the split decision, docs/method.md section 3.8): the even
// half's mean scattered around L_u, its share of the samples between 0.4 and 0.6 (0 and 1 at a few
// pixels), each half's variance estimate scattered around Var[L_u], some unknown.
struct Halves {
  Image halves = Image::rgba(W, H), variances{W, H, {"even", "odd"}};
};
Halves make_halves(const Scenario& s, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u01(0.0f, 1.0f);
  Halves h;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const float r = u01(rng);
      h.halves.at(x, y, 3) = r < 0.03f ? 0.0f : r > 0.97f ? 1.0f : 0.4f + 0.2f * u01(rng);
      for (int c = 0; c < 3; ++c) h.halves.at(x, y, c) = s.hv.at(x, y, c) * (0.3f + 1.4f * u01(rng));
      for (int k = 0; k < 2; ++k) {
        const float v = s.var.at(x, y, 0);
        h.variances.at(x, y, k) = u01(rng) < 0.08f ? kVarUnknown : v < 0.0f ? v : v * (0.2f + 1.8f * u01(rng));
      }
    }
  return h;
}

TEST(BlendVsCpu, SplitDecisionMatchesReference) {
  test::osmesa_context();
  Scenario s = make_scenario(23);
  fill_surface(s, 23);
  const Halves h = make_halves(s, 29);
  GpuFixture gpu(s);
  gpu.inputs.upload_halves(h.halves, h.variances);
  FilterParams fp;
  fp.skip_case2 = false;
  FilterOutput ref_f = cpu_filter(s.hv, s.var, s.lv, s.range, s.depth, fp, 0.02f);
  const Texture2D filtered = filtered_texture(ref_f);
  const Texture2D centre_weight = [&] {
    Texture2D tex(W, H, TextureFormat::R32F);
    tex.upload(ref_f.centre_weight);
    return tex;
  }();
  for (float t : {0.001f, 0.02f})
    for (int pool : {0, 1})
      for (bool guard : {false, true}) {
        SCOPED_TRACE(testing::Message() << "t=" << t << " pool=" << pool << " guard=" << guard);
        BlendPass blend(W, H);
        const BlendParams bp{range_weights(fp), guard, 64.0f, true};
        blend.run(gpu.inputs, &filtered, pool ? &gpu.guide : nullptr, t, bp, &centre_weight,
                  pool ? &gpu.surface : nullptr);
        const BlendOutput ref = cpu_blend(s.lv, s.hv, s.var, &ref_f, t, bp, pool ? &s.range : nullptr,
                                          pool ? &s.depth : nullptr, pool ? &s.surface : nullptr,
                                          BlendHalves{&h.halves, &h.variances});
        expect_close(blend.final_image(), ref.final_rgb, 1e-4f, 1e-6f, "final");
        expect_close(blend.s_image(), ref.s, 1e-4f, 1e-5f, "s");
        expect_close(blend.case_image(), ref.blend_case, 0.0f, 0.0f, "case");
        // The inspector decides a pixel again as the pass did.
        const BlendInspection i = blend.inspect(5, 7);
        EXPECT_TRUE(i.split);
        EXPECT_NEAR(i.decision.s, ref.s.at(5, 7, 0), 1e-4f);
        // The split changes the image: where the halves disagree it is not the one decision's.
        const BlendOutput one = cpu_blend(s.lv, s.hv, s.var, &ref_f, t, BlendParams{range_weights(fp), guard, 64.0f},
                                          pool ? &s.range : nullptr, pool ? &s.depth : nullptr,
                                          pool ? &s.surface : nullptr);
        EXPECT_NE(one.s.pixels, ref.s.pixels);
      }
}

// Where both halves hold the whole pixel's mean and variance, the split decision is the one decision,
// bit for bit: each half decides what the pixel would, and the halves' difference term is 0. (With
// the bias guard it is not: the guard judges the pixel alone on the other half's mean, whose
// variance is twice the whole mean's.)
TEST(BlendVsCpu, SplitDecisionOfEqualHalvesIsTheOneDecision) {
  Scenario s = make_scenario(31);
  Halves h;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      for (int c = 0; c < 3; ++c) h.halves.at(x, y, c) = s.hv.at(x, y, c);
      h.halves.at(x, y, 3) = 0.5f;
      h.variances.at(x, y, 0) = h.variances.at(x, y, 1) = s.var.at(x, y, 0);
    }
  FilterParams fp;
  const FilterOutput f = cpu_filter(s.hv, s.var, s.lv, s.range, s.depth, fp, 0.02f);
  const BlendOutput one = cpu_blend(s.lv, s.hv, s.var, &f, 0.005f, BlendParams{range_weights(fp), false, 64.0f},
                                    &s.range, &s.depth);
  const BlendOutput split = cpu_blend(s.lv, s.hv, s.var, &f, 0.005f, BlendParams{range_weights(fp), false, 64.0f, true},
                                      &s.range, &s.depth, nullptr, BlendHalves{&h.halves, &h.variances});
  EXPECT_EQ(split.final_rgb.pixels, one.final_rgb.pixels);
  EXPECT_EQ(split.blend_case.pixels, one.blend_case.pixels);
}

// The filter's skip by halves (shared::skip_as_case2_by_halves) in every variant and in the
// demodulation pass, against the CPU reference; it skips only pixels both halves would leave.
TEST(FilterVsCpu, SkipByHalvesMatchesReference) {
  test::osmesa_context();
  Scenario s = make_scenario(37);
  const Halves h = make_halves(s, 41);
  GpuFixture gpu(s);
  gpu.inputs.upload_halves(h.halves, h.variances);
  const float t = 0.02f;
  for (FilterKind kind : {FilterKind::BilateralDepth, FilterKind::Atrous, FilterKind::Subsampled, FilterKind::Grid}) {
    SCOPED_TRACE(filter_kind_name(kind));
    FilterParams p;
    p.kind = kind;
    p.split = true;
    FilterPass filter(W, H);
    filter.run(gpu.inputs, gpu.guide, p, t);
    const FilterOutput ref = cpu_filter(s.hv, s.var, s.lv, s.range, s.depth, p, t, nullptr, &h.variances);
    int skipped = 0, skipped_by_own = 0;
    FilterParams own = p;
    own.split = false;
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        const bool by_halves =
            case2_skip_decision(s.hv, s.var, s.lv, s.range, s.depth, p, t, x, y, nullptr, &h.variances);
        skipped += by_halves;
        skipped_by_own += case2_skip_decision(s.hv, s.var, s.lv, s.range, s.depth, own, t, x, y);
        if (by_halves) {
          EXPECT_EQ(ref.variance.at(x, y, 0), kVarSkipped) << x << "," << y;
        }
      }
    EXPECT_EQ(filter.filtered_pixels(), static_cast<uint32_t>(W * H - skipped));
    EXPECT_GT(skipped, 0);
    EXPECT_NE(skipped, skipped_by_own);
  }
  FilterParams p;
  p.split = true;
  Demodulation demod(W, H);
  Image albedo = Image::rgb(W, H, 0.5f);
  gpu.inputs.upload_albedo(albedo);
  demod.demodulate(gpu.inputs, gpu.guide, p, t);
  const DemodulatedInputs ref =
      cpu_demodulate(s.hv, s.var, s.lv, albedo, s.range, s.depth, p, t, nullptr, &h.variances);
  expect_close(demod.filter_inputs().lv_image(), ref.lv, 0.0f, 0.0f, "the skip decision");
}

// The bias guard on a flat surface: L_u = m + Gaussian noise of the variance Var[L_u] says, L_f = m + b with Var[L_f] = 0.
// Unbiased (b = 0) the 5x5 mean of d = L_f - L_u is N(0, Var[L_u] / 25), and the 2-sigma test
// fires in P(|Z| > 2) = 4.6 % of the pixels (the pixel's own test, at 2.5 sigma, mostly where the
// window's does too); with b = 2 sigma of a single pixel (z = 10 for the mean) it fires in all of
// them, and s becomes the least-error blend factor for the measured bias, (b^2 + f) / (b^2 + f + u)
// with f = 0: 0.8 for the window's b^2 = 4 u, 5/6 for the pixel's, whose (b + noise)^2 averages
// b^2 + u; the guard keeps the larger, so s averages a little above 0.83.
TEST(BlendVsCpu, BiasGuardFiresWhereLfIsBiasedAndRarelyWhereItIsNot) {
  constexpr int kSize = 64;
  const float sigma = 0.1f, m = 1.0f, t = 1e-4f;  // u = sigma^2 / m^2 = 0.01 > t: the blend mixes
  std::mt19937 rng(5);
  std::normal_distribution<float> noise(0.0f, sigma);
  Image lv = Image::rgb(kSize, kSize), hv = Image::rgb(kSize, kSize), var = Image::gray(kSize, kSize);
  Image range = Image::rgb(kSize, kSize), depth = Image::gray(kSize, kSize);
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      const float v = m + noise(rng);
      for (int c = 0; c < 3; ++c) {
        hv.at(x, y, c) = v;
        range.at(x, y, c) = 0.5f;
      }
      var.at(x, y, 0) = sigma * sigma;
      depth.at(x, y, 0) = 2.0f;
    }
  BlendParams guarded{range_weights(FilterParams{}), true};
  for (float bias : {0.0f, 2.0f * sigma}) {
    SCOPED_TRACE(testing::Message() << "bias=" << bias);
    FilterOutput f;
    f.filtered = Image::rgb(kSize, kSize);
    f.variance = Image::gray(kSize, kSize);
    for (float& c : f.filtered.pixels) c = m + bias;
    const BlendOutput out = cpu_blend(lv, hv, var, &f, t, guarded, &range, &depth);
    size_t fired = 0, judged = 0;
    double s_sum = 0;
    for (int y = 1; y < kSize - 1; ++y)
      for (int x = 1; x < kSize - 1; ++x) {
        ++judged;
        const bool raised = out.blend_case.at(x, y, 0) == float(kCaseBiasGuard);
        fired += raised;
        if (raised) s_sum += out.s.at(x, y, 0);
      }
    const double share = double(fired) / judged;
    std::printf("bias %g: the guard fired in %.1f %% of the pixels, mean s there %.3f\n", bias, 100 * share,
                fired ? s_sum / fired : 0.0);
    if (bias == 0.0f) {
      EXPECT_GT(share, 0.02);
      EXPECT_LT(share, 0.08);
    } else {
      EXPECT_GT(share, 0.99);
      EXPECT_NEAR(s_sum / fired, 0.84, 0.02);
    }
  }
  // The noise the guard trades against is its window's, whatever its range colour: rows of two
  // range colours, the even rows reporting Var[L_u] = sigma^2 / 100 (as a pixel that missed the
  // rare bright paths does), the odd ones sigma^2. The blend's own u of an even-row pixel pools its
  // own colour only (sigma^2 / 100). Every window finds the bias (L_u = m, L_f = m + 2 sigma
  // exactly), and the guard takes the one asking for the largest s: a half window of 3 rows (2 even,
  // 1 odd), mean 0.34 sigma^2 (the 5x5 window's is 0.406 sigma^2, 3 even rows and 2 odd):
  // s = 4 / (4 + 0.34) = 0.922, where the blend's u would give 4 / 4.01 = 0.998.
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      for (int c = 0; c < 3; ++c) {
        hv.at(x, y, c) = m;
        range.at(x, y, c) = y % 2 ? 0.9f : 0.1f;
      }
      var.at(x, y, 0) = y % 2 ? sigma * sigma : sigma * sigma / 100;
    }
  FilterOutput f;
  f.filtered = Image::rgb(kSize, kSize);
  f.variance = Image::gray(kSize, kSize);
  for (float& c : f.filtered.pixels) c = m + 2 * sigma;
  const BlendOutput out = cpu_blend(lv, hv, var, &f, t / 100, guarded, &range, &depth);  // u > t in every row
  for (int y = 2; y < kSize - 2; y += 2)
    for (int x = 2; x < kSize - 2; ++x) {
      ASSERT_EQ(out.blend_case.at(x, y, 0), float(kCaseBiasGuard)) << x << "," << y;
      ASSERT_NEAR(out.s.at(x, y, 0), 4.0 / 4.34, 1e-4) << x << "," << y;
    }
}

// A bias on one side of a sharp change the guide does not show, as where a focused caustic meets the
// contact shadow under a glass sphere: one range colour; on the "caustic" side L_u = 1 with a large
// Var[L_u] (0.25), on the "shadow" side L_u = 0.01 with a small one (1e-4); the filter has moved
// light across the change, L_f = 0.7 in the caustic's two rows next to it and 0.3 in the shadow's
// two. There the 5x5 window holds about as much d < 0 as d > 0 and the caustic's variance, so its
// test finds nothing; the half window on the shadow side holds the bias alone, with the shadow's
// variance. In all four orientations (each half window), CPU and GPU.
TEST(BlendVsCpu, BiasGuardFindsABiasOnOneSideOfASharpChange) {
  test::osmesa_context();
  const float v_caustic = 0.25f, v_shadow = 1e-4f, t = 1e-5f;
  for (int orientation = 0; orientation < 4; ++orientation) {
    SCOPED_TRACE(testing::Message() << "orientation " << orientation);
    // k: the distance into the shadow side (k >= 0), across the change.
    auto k_of = [&](int x, int y) {
      switch (orientation) {
        case 0: return y - H / 2;
        case 1: return H / 2 - y;
        case 2: return x - W / 2;
        default: return W / 2 - x;
      }
    };
    Scenario s;
    FilterOutput f{Image::rgb(W, H), Image::gray(W, H), Image()};
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        const int k = k_of(x, y);
        const float lu = k >= 0 ? 0.01f : 1.0f;
        const float lf = (k == 0 || k == 1) ? 0.3f : (k == -1 || k == -2) ? 0.7f : lu;
        for (int c = 0; c < 3; ++c) {
          s.hv.at(x, y, c) = lu;
          s.range.at(x, y, c) = 0.5f;
          f.filtered.at(x, y, c) = lf;
        }
        s.var.at(x, y, 0) = k >= 0 ? v_shadow : v_caustic;
        s.depth.at(x, y, 0) = 2.0f;
        f.variance.at(x, y, 0) = 1e-6f;
      }
    const BlendParams guarded{range_weights(FilterParams{}), true};
    const BlendOutput out = cpu_blend(s.lv, s.hv, s.var, &f, t, guarded, &s.range, &s.depth);
    size_t checked = 0;
    for (int y = 2; y < H - 2; ++y)
      for (int x = 2; x < W - 2; ++x) {
        const int k = k_of(x, y);
        if (k != 0 && k != 1) continue;
        // The 5x5 window's own test (kBiasGuardZ) finds nothing here.
        double d_sum = 0, var_sum = 0;
        for (int dy = -2; dy <= 2; ++dy)
          for (int dx = -2; dx <= 2; ++dx) {
            d_sum += f.filtered.at(x + dx, y + dy, 1) - s.hv.at(x + dx, y + dy, 1);
            var_sum += s.var.at(x + dx, y + dy, 0) + f.variance.at(x + dx, y + dy, 0);
          }
        ASSERT_LT(std::abs(d_sum / 25), shared::kBiasGuardZ * std::sqrt(var_sum) / 25) << x << "," << y;
        ASSERT_EQ(out.blend_case.at(x, y, 0), float(kCaseBiasGuard)) << x << "," << y;
        // Next to the change the blend's u pools the caustic's variance, which keeps s low; one
        // pixel further in, the shadow's own noise is all the guard trades against.
        ASSERT_GT(out.s.at(x, y, 0), k == 0 ? 0.2f : 0.95f) << x << "," << y;
        ++checked;
      }
    EXPECT_GE(checked, 50u);  // 2 rows or columns of 25 or more
    expect_gpu_blend_matches(s, f, t, guarded, out);
  }
}

// A bias that changes sign from pixel to pixel, as where the filter blurs the detail of a normal map
// or of a reflection: L_u a checkerboard of 1 +- 0.5 with Var[L_u] = 0.01, L_f = 1. Every window of
// 5 or 15 pixels holds about as many d > 0 as d < 0 and finds nothing (the 5x5 window's mean |d| is
// 0.02 against 2 sigma = 0.04); the pixel alone, |d| = 0.5 against 2.5 sigma = 0.25, finds it, and s
// becomes the least-error factor b^2 / (b^2 + u) = 0.25 / 0.26. CPU and GPU.
TEST(BlendVsCpu, BiasGuardFindsABiasThatChangesSignFromPixelToPixel) {
  test::osmesa_context();
  const float t = 1e-5f;
  Scenario s;
  FilterOutput f{Image::rgb(W, H), Image::gray(W, H), Image()};
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const float lu = (x + y) % 2 ? 1.5f : 0.5f;
      for (int c = 0; c < 3; ++c) {
        s.hv.at(x, y, c) = lu;
        s.range.at(x, y, c) = 0.5f;
        f.filtered.at(x, y, c) = 1.0f;
      }
      s.var.at(x, y, 0) = 0.01f;
      s.depth.at(x, y, 0) = 2.0f;
    }
  const BlendParams guarded{range_weights(FilterParams{}), true};
  const BlendOutput out = cpu_blend(s.lv, s.hv, s.var, &f, t, guarded, &s.range, &s.depth);
  for (int y = 2; y < H - 2; ++y)
    for (int x = 2; x < W - 2; ++x) {
      ASSERT_EQ(out.blend_case.at(x, y, 0), float(kCaseBiasGuard)) << x << "," << y;
      ASSERT_NEAR(out.s.at(x, y, 0), 0.25f / 0.26f, 1e-4f) << x << "," << y;
    }
  expect_gpu_blend_matches(s, f, t, guarded, out);
}

// The full bilateral's centre weight feeds the blend's covariance term: GPU against CPU, and the
// term changes s where the blend mixes (it can only lower s or keep it).
TEST(BlendVsCpu, CovarianceTermFromTheFiltersCentreWeight) {
  test::osmesa_context();
  Scenario s = make_scenario(13);
  // A step in HV the guide does not show (a shadow edge on one surface): the filter smooths it,
  // which gives the bias guard below something to find.
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W / 3; ++x)
      for (int c = 0; c < 3; ++c) s.hv.at(x, y, c) *= 4.0f;
  GpuFixture gpu(s);
  FilterParams fp;
  fp.kind = FilterKind::BilateralDepth;
  fp.sigma_s = 2.0f;
  FilterPass filter(W, H);
  BlendPass blend(W, H);
  FilterOutput ref_f = cpu_filter(s.hv, s.var, s.lv, s.range, s.depth, fp, test::kTestThreshold);
  FilterOutput ref_plain = ref_f;
  ref_plain.centre_weight = Image();
  size_t changed = 0, guarded_pixels = 0;
  for (float t : {0.001f, 0.02f, 0.2f}) {
    SCOPED_TRACE(testing::Message() << "t=" << t);
    filter.run(gpu.inputs, gpu.guide, fp, t);
    ASSERT_NE(filter.centre_weight(), nullptr);
    const BlendParams bp{range_weights(fp)};
    blend.run(gpu.inputs, &filter, gpu.guide, t, bp);
    ref_f = cpu_filter(s.hv, s.var, s.lv, s.range, s.depth, fp, t);
    BlendOutput ref = cpu_blend(s.lv, s.hv, s.var, &ref_f, t, bp, &s.range, &s.depth);
    ref_plain = ref_f;
    ref_plain.centre_weight = Image();
    BlendOutput plain = cpu_blend(s.lv, s.hv, s.var, &ref_plain, t, bp, &s.range, &s.depth);
    expect_close(blend.s_image(), ref.s, 1e-4f, 1e-4f, "s");
    expect_close(blend.case_image(), ref.blend_case, 0.0f, 0.0f, "case");
    for (size_t i = 0; i < ref.s.pixels.size(); ++i) {
      EXPECT_LE(ref.s.pixels[i], plain.s.pixels[i] + 1e-6f) << i;
      changed += ref.s.pixels[i] < plain.s.pixels[i] - 1e-3f;
    }
    // The bias guard takes the same covariance into its least-error s.
    const BlendParams guarded{range_weights(fp), true};
    blend.run(gpu.inputs, &filter, gpu.guide, t, guarded);
    BlendOutput ref_guarded = cpu_blend(s.lv, s.hv, s.var, &ref_f, t, guarded, &s.range, &s.depth);
    expect_close(blend.s_image(), ref_guarded.s, 1e-4f, 1e-4f, "s, guarded");
    expect_close(blend.case_image(), ref_guarded.blend_case, 0.0f, 0.0f, "case, guarded");
    guarded_pixels += blend.case_counts()[kCaseBiasGuard];
  }
  EXPECT_GT(changed, 0u);
  EXPECT_GT(guarded_pixels, 0u);
}

TEST(BlendVsCpu, BackgroundPixelsWithoutHvTakeNoFilteredLight) {
  // The left third is background (guide distance kBackgroundDepth, the camera rays escaped): where
  // L_u is exactly 0 there, the blend keeps it (case 2, s = 1) however bright the filtered light
  // spread into it; background pixels with HV light, and surfaces, blend as before. GPU = CPU.
  test::osmesa_context();
  Scenario s = make_scenario(21);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W / 3; ++x) {
      s.depth.at(x, y, 0) = kBackgroundDepth;
      if ((x + y) % 4 != 0)
        for (int c = 0; c < 3; ++c) s.hv.at(x, y, c) = 0.0f;
      if ((x + y) % 4 != 0) s.var.at(x, y, 0) = 0.0f;
    }
  GpuFixture gpu(s);
  FilterParams fp;
  fp.kind = FilterKind::Grid;
  const float t = 0.01f;
  FilterPass filter(W, H);
  filter.run(gpu.inputs, gpu.guide, fp, t);
  FilterOutput ref_f = cpu_filter(s.hv, s.var, s.lv, s.range, s.depth, fp, t);
  const BlendParams bp{range_weights(fp)};
  BlendPass blend(W, H);
  blend.run(gpu.inputs, &filter, gpu.guide, t, bp);
  BlendOutput ref = cpu_blend(s.lv, s.hv, s.var, &ref_f, t, bp, &s.range, &s.depth);
  expect_close(blend.s_image(), ref.s, 1e-4f, 1e-4f, "s");
  expect_close(blend.case_image(), ref.blend_case, 0.0f, 0.0f, "case");
  int background = 0, other_cases = 0;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const bool empty_background = x < W / 3 && (x + y) % 4 != 0;
      if (empty_background) {
        ++background;
        EXPECT_EQ(ref.s.at(x, y, 0), 1.0f) << x << ", " << y;
        EXPECT_EQ(ref.blend_case.at(x, y, 0), float(kCaseUnfiltered)) << x << ", " << y;
      } else {
        other_cases += ref.blend_case.at(x, y, 0) != float(kCaseUnfiltered);
      }
    }
  EXPECT_GT(background, 0);
  EXPECT_GT(other_cases, 0) << "the rest still blends";
}

// Pixels whose HV samples were all 0 (variance 0) beside lit neighbours: filtered at few samples,
// unfiltered (case 2) once the zero-variance rule's decay brings their u below t; the pass as its
// CPU reference, with the pixels' own counts read from the threshold factors of adaptive sampling.
TEST(BlendVsCpu, ZeroVariancePixelsLeaveTheFilterAsSamplesGrow) {
  test::osmesa_context();
  Scenario s = make_scenario(29);
  Image lv_rgba = Image::rgba(W, H);
  std::vector<size_t> zero;
  for (size_t i = 0; i < s.lv.pixel_count(); ++i) {
    for (int c = 0; c < 3; ++c) lv_rgba.pixels[4 * i + c] = s.lv.pixels[3 * i + c];
    lv_rgba.pixels[4 * i + 3] = 1.0f;
    if (i % 7 == 3) {
      zero.push_back(i);
      for (int c = 0; c < 3; ++c) s.hv.pixels[3 * i + c] = 0.0f;
      s.var.pixels[i] = 0.0f;
    }
  }
  FilterParams fp;
  FilterOutput ref_f = cpu_filter(s.hv, s.var, s.lv, s.range, s.depth, fp, 0.0f);
  ref_f.centre_weight = Image();  // the blend gets L_f as a plain texture, without a centre weight
  const Texture2D filtered = filtered_texture(ref_f);
  const float t = 0.01f;
  auto zero_pixels_in_case2 = [&](const Image& cases) {
    size_t n = 0;
    for (size_t i : zero) n += cases.pixels[i] == float(kCaseUnfiltered);
    return n;
  };
  size_t previous = 0;
  for (float samples : {0.0f, 64.0f, 1e5f, 1e8f}) {
    SCOPED_TRACE(testing::Message() << "samples=" << samples);
    PreviewInputs inputs(W, H);
    inputs.upload(lv_rgba, s.hv, s.var);
    BlendParams bp{range_weights(fp), false, samples};
    BlendPass blend(W, H);
    blend.run(inputs, &filtered, nullptr, t, bp);
    const BlendOutput ref = cpu_blend(lv_rgba, s.hv, s.var, &ref_f, t, bp, nullptr, nullptr);
    expect_close(blend.case_image(), ref.blend_case, 0.0f, 0.0f, "case");
    expect_close(blend.final_image(), ref.final_rgb, 1e-4f, 1e-6f, "final");
    const size_t clean = zero_pixels_in_case2(ref.blend_case);
    EXPECT_GE(clean, previous);
    if (samples <= kZeroVarianceSamples) {
      EXPECT_LT(clean, zero.size() / 2) << "few samples all 0 are no evidence of low variance";
    }
    if (samples == 1e8f) {
      EXPECT_EQ(clean, zero.size());
    }
    previous = clean;
  }
  // The same pixels at their own counts under adaptive sampling: a run of 64 frames whose
  // zero-variance pixels hold 1e8 samples each (threshold factor t_{1e8} / t_64) are all clean.
  for (size_t i : zero) lv_rgba.pixels[4 * i + 3] = effective_threshold(t, 100000000u) / effective_threshold(t, 64);
  PreviewInputs inputs(W, H);
  inputs.upload(lv_rgba, s.hv, s.var);
  const BlendParams bp{range_weights(fp), false, 64.0f};
  BlendPass blend(W, H);
  blend.run(inputs, &filtered, nullptr, effective_threshold(t, 64), bp);
  const BlendOutput ref = cpu_blend(lv_rgba, s.hv, s.var, &ref_f, effective_threshold(t, 64), bp, nullptr, nullptr);
  expect_close(blend.case_image(), ref.blend_case, 0.0f, 0.0f, "case");
  EXPECT_EQ(zero_pixels_in_case2(ref.blend_case), zero.size());
}

TEST(BlendVsCpu, NoFilteredValueMeansUnfiltered) {
  test::osmesa_context();
  Scenario s = make_scenario(5);
  GpuFixture gpu(s);
  BlendPass blend(W, H);
  blend.run(gpu.inputs, nullptr, gpu.guide, 0.01f, {});
  BlendOutput ref = cpu_blend(s.lv, s.hv, s.var, nullptr, 0.01f, {}, &s.range, &s.depth);
  expect_close(blend.final_image(), ref.final_rgb, 1e-5f, 1e-7f, "final");
  EXPECT_EQ(blend.case_counts()[kCaseNoFiltered], uint32_t(W * H));
}

// The tone-map pass stays finite for extreme finite inputs and matches its CPU reference there: a
// bright pixel under a tiny log-average or white point is white, not black or NaN.
TEST(TonemapPass, ExtremeFiniteInputsGiveFiniteDisplayValuesLikeTheCpu) {
  test::osmesa_context();
  Image hdr = Image::rgba(4, 1, 1.0f), rgb = Image::rgb(4, 1, 0.0f);
  const float values[4] = {1e30f, 3.4e38f, 1e-30f, 0.0f};
  for (int x = 0; x < 4; ++x)
    for (int c = 0; c < 3; ++c) hdr.at(x, 0, c) = rgb.at(x, 0, c) = values[x];
  hdr.at(3, 0, 0) = rgb.at(3, 0, 0) = 1e30f;
  Texture2D texture(4, 1, TextureFormat::RGBA32F);
  texture.upload(hdr);
  TonemapPass pass(4, 1);
  for (float log_average : {0.0f, 1e-20f})
    for (float white : {0.0f, 1e-3f}) {
      TonemapParams p;
      p.log_average = log_average;
      p.white = white;
      pass.run(texture, p);
      const Image display = pass.display_image();
      const std::string what = "log_average " + std::to_string(log_average) + ", white " + std::to_string(white);
      EXPECT_EQ(count_nonfinite(display), 0u) << what;
      expect_close(display, cpu_tonemap(rgb, p), 2e-4f, 2e-5f, what.c_str());
      EXPECT_NEAR(display.at(0, 0, 0), 1.0f, 1e-5f) << what;
      EXPECT_NEAR(display.at(3, 0, 1), 0.0f, 1e-5f) << what;
    }
}

TEST(FullChain, FilterBlendTonemapOnGpuMatchesCpu) {
  test::osmesa_context();
  Scenario s = make_scenario(21);
  GpuFixture gpu(s);
  FilterParams fp;
  const float t = 0.01f;
  FilterPass filter(W, H);
  BlendPass blend(W, H);
  TonemapPass tonemap(W, H);
  filter.run(gpu.inputs, gpu.guide, fp, t);
  const BlendParams bp{range_weights(fp)};
  blend.run(gpu.inputs, &filter, gpu.guide, t, bp);
  tonemap.run(blend.output(), {});
  FilterOutput rf = cpu_filter(s.hv, s.var, s.lv, s.range, s.depth, fp, t);
  BlendOutput rb = cpu_blend(s.lv, s.hv, s.var, &rf, t, bp, &s.range, &s.depth);
  expect_close(blend.final_image(), rb.final_rgb, 2e-4f, 1e-6f, "final");
  expect_close(tonemap.display_image(), cpu_tonemap(rb.final_rgb, {}), 2e-4f, 2e-5f, "display");
  for (const Image& im : {filter.filtered_image(), filter.variance_image(), blend.final_image(), blend.s_image(),
                          blend.case_image(), tonemap.display_image()})
    EXPECT_EQ(count_nonfinite(im), 0u);
}

// Adaptive sampling: each pixel's threshold is t times the factor in its L_lv texel's alpha
// (shared::pixel_threshold). The filter's skip and the blend read it on the GPU as the CPU
// reference does, and the factors change the decisions (so the test fails if they are ignored).
TEST(PixelThreshold, FactorsInTheLvAlphaReachTheSkipAndTheBlend) {
  test::osmesa_context();
  Scenario s = make_scenario(23);
  Image lv_rgba = Image::rgba(W, H);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> factor(0.05f, 3.0f);
  for (size_t i = 0; i < s.lv.pixel_count(); ++i) {
    for (int c = 0; c < 3; ++c) lv_rgba.pixels[4 * i + c] = s.lv.pixels[3 * i + c];
    lv_rgba.pixels[4 * i + 3] = factor(rng);
  }
  PreviewInputs inputs(W, H);
  inputs.upload(lv_rgba, s.hv, s.var);
  Texture2D guide(W, H, TextureFormat::RGBA32F);
  guide.upload(guide_image(s));
  const float t = 0.01f;
  for (FilterKind kind : {FilterKind::BilateralDepth, FilterKind::Grid, FilterKind::Atrous}) {
    SCOPED_TRACE(filter_kind_name(kind));
    FilterParams fp;
    fp.kind = kind;
    FilterPass filter(W, H);
    filter.run(inputs, guide, fp, t);
    const FilterOutput ref = cpu_filter(s.hv, s.var, lv_rgba, s.range, s.depth, fp, t);
    const FilterOutput uniform = cpu_filter(s.hv, s.var, s.lv, s.range, s.depth, fp, t);
    size_t skipped = 0, skipped_uniform = 0;
    for (size_t i = 0; i < ref.variance.pixels.size(); ++i) {
      skipped += ref.variance.pixels[i] == kVarSkipped;
      skipped_uniform += uniform.variance.pixels[i] == kVarSkipped;
    }
    EXPECT_EQ(filter.filtered_pixels(), W * H - skipped);
    EXPECT_NE(skipped, skipped_uniform) << "the factors changed no skip decision";
    expect_close(filter.raw_variance_image(), ref.variance, 1e-4f, 1e-12f, "Var[L_f]");
    const BlendParams bp{range_weights(fp), true};
    BlendPass blend(W, H);
    blend.run(inputs, &filter, guide, t, bp);
    const BlendOutput ref_blend = cpu_blend(lv_rgba, s.hv, s.var, &ref, t, bp, &s.range, &s.depth);
    const BlendOutput uniform_blend = cpu_blend(s.lv, s.hv, s.var, &ref, t, bp, &s.range, &s.depth);
    expect_close(blend.case_image(), ref_blend.blend_case, 0.0f, 0.0f, "case");
    expect_close(blend.s_image(), ref_blend.s, 1e-4f, 1e-5f, "s");
    expect_close(blend.final_image(), ref_blend.final_rgb, 1e-4f, 1e-6f, "final");
    EXPECT_NE(ref_blend.s.pixels, uniform_blend.s.pixels) << "the factors changed no blend factor";
  }
  // A factor of 1 everywhere is the uniform threshold, bit for bit.
  for (size_t i = 0; i < s.lv.pixel_count(); ++i) lv_rgba.pixels[4 * i + 3] = 1.0f;
  FilterParams fp;
  const FilterOutput ref = cpu_filter(s.hv, s.var, s.lv, s.range, s.depth, fp, t);
  EXPECT_EQ(cpu_blend(lv_rgba, s.hv, s.var, &ref, t, {}, &s.range, &s.depth).final_rgb.pixels,
            cpu_blend(s.lv, s.hv, s.var, &ref, t, {}, &s.range, &s.depth).final_rgb.pixels);
}

TEST(TonemapVsCpu, MatchesReference) {
  test::osmesa_context();
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u01(0.0f, 1.0f);
  Image hdr = Image::rgb(W, H);
  for (float& v : hdr.pixels) v = std::pow(10.0f, 4.0f * u01(rng) - 3.0f);
  hdr.at(0, 0, 0) = kNaN;
  hdr.at(1, 0, 1) = kInf;
  hdr.at(2, 0, 2) = -1.0f;
  hdr.at(3, 0, 0) = 1e30f;
  for (int c = 0; c < 3; ++c) hdr.at(4, 0, c) = 0.0f;
  Texture2D tex(W, H, TextureFormat::RGBA32F);
  tex.upload(hdr);
  TonemapPass tonemap(W, H);
  for (TonemapParams p : {TonemapParams{}, TonemapParams{0.36f, 2.0f, 0.0f, 1e-4f}, TonemapParams{0.18f, 0.0f, 0.5f, 1e-4f}}) {
    tonemap.run(tex, p);
    Image gpu = tonemap.display_image();
    expect_close(gpu, cpu_tonemap(hdr, p), 1e-4f, 2e-5f, "display");
    for (float v : gpu.pixels) {
      EXPECT_GE(v, 0.0f);
      EXPECT_LE(v, 1.0f);
    }
    if (p.log_average == 0) {
      double ref = cpu_log_average(hdr, p.delta);
      EXPECT_NEAR(tonemap.log_average(), ref, 1e-4 * ref);
    }
  }
}

// ---- Albedo demodulation (gl/demodulation.h) ----

// A textured albedo: a fine checkerboard of two colors, a black and a nearly black stripe (not
// demodulated), and a few non-finite texels.
Image albedo_image_for_test() {
  Image a = Image::rgb(W, H);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const bool odd = ((x / 2) + (y / 2)) % 2 == 1;
      const float color[3] = {odd ? 0.8f : 0.15f, odd ? 0.6f : 0.3f, odd ? 0.9f : 0.05f};
      for (int c = 0; c < 3; ++c) a.at(x, y, c) = x == 3 ? 0.0f : color[c];
      if (x == 5)  // luminance below the epsilon: not demodulated
        for (int c = 0; c < 3; ++c) a.at(x, y, c) = 0.5f * kAlbedoEpsilon;
    }
  a.at(7, 2, 0) = kNaN;
  a.at(8, 2, 2) = kInf;
  return a;
}

// Demodulate, filter (every variant, with and without the case-2 skip), remodulate, blend: the GPU
// chain against cpu_demodulate -> cpu_filter -> cpu_remodulate -> cpu_blend, and the skip decisions
// equal to those of the filter without demodulation.
class DemodulationVsCpu : public ::testing::TestWithParam<std::tuple<FilterKind, bool>> {};

TEST_P(DemodulationVsCpu, MatchesReference) {
  test::osmesa_context();
  auto [kind, skip] = GetParam();
  Scenario s = make_scenario(13);
  const Image albedo = albedo_image_for_test();
  GpuFixture gpu(s);
  gpu.inputs.upload_albedo(albedo);
  FilterParams p;
  p.kind = kind;
  p.skip_case2 = skip;
  const float t = 0.05f;
  Demodulation demod(W, H);
  FilterPass filter(W, H);
  // With the surface buffer throughout: its terms reach the skip decision and the filter.
  demod.demodulate(gpu.inputs, gpu.guide, p, t, &gpu.surface);
  filter.run(demod.filter_inputs(), gpu.guide, p, t, &gpu.surface);
  demod.remodulate(filter.output(), gpu.inputs);

  const DemodulatedInputs d = cpu_demodulate(s.hv, s.var, s.lv, albedo, s.range, s.depth, p, t, &s.surface);
  expect_close(demod.filter_inputs().hv_image(), d.hv, 1e-5f, 1e-7f, "L_u / a");
  expect_close(demod.filter_inputs().var_image(), [&] {
    Image v = d.var_u;
    for (float& x : v.pixels) x = x > 0 ? x : 0.0f;
    return v;
  }(), 1e-5f, 1e-12f, "Var[L_u] / Y(a)^2");
  const FilterOutput ref = cpu_remodulate(cpu_filter(d.hv, d.var_u, d.lv, s.range, s.depth, p, t, &s.surface), albedo);
  expect_close(demod.filtered_image(), ref.filtered, 1e-4f, 1e-7f, "L_f");
  Image gpu_var = demod.output().download({"R", "G", "B", "A"});
  Image gpu_raw_var = Image::gray(W, H);
  for (size_t i = 0; i < gpu_raw_var.pixel_count(); ++i) gpu_raw_var.pixels[i] = gpu_var.pixels[4 * i + 3];
  expect_close(gpu_raw_var, ref.variance, 1e-4f, 1e-12f, "Var[L_f]");

  // The same pixels are skipped as without demodulation.
  FilterPass plain(W, H);
  plain.run(gpu.inputs, gpu.guide, p, t, &gpu.surface);
  EXPECT_EQ(filter.filtered_pixels(), plain.filtered_pixels());
  const FilterOutput plain_ref = cpu_filter(s.hv, s.var, s.lv, s.range, s.depth, p, t, &s.surface);
  size_t skipped = 0;
  for (size_t i = 0; i < ref.variance.pixels.size(); ++i) {
    EXPECT_EQ(ref.variance.pixels[i] == kVarSkipped, plain_ref.variance.pixels[i] == kVarSkipped) << i;
    skipped += ref.variance.pixels[i] == kVarSkipped;
  }
  if (skip) {
    EXPECT_GT(skipped, 0u);
  }

  // The blend sees the remodulated L_f and Var[L_f].
  const BlendParams bp{range_weights(p)};
  BlendPass blend(W, H);
  // The filter's centre weight (bilateral variants) is unchanged by demodulation: Cov[L_u, L_f] =
  // w Var[L_u] with a grey factor.
  blend.run(gpu.inputs, &demod.output(), &gpu.guide, t, bp, filter.centre_weight(), &gpu.surface);
  const BlendOutput rb = cpu_blend(s.lv, s.hv, s.var, &ref, t, bp, &s.range, &s.depth, &s.surface);
  expect_close(blend.final_image(), rb.final_rgb, 2e-4f, 1e-6f, "final");
  expect_close(blend.case_image(), rb.blend_case, 0.0f, 0.0f, "case");
}

INSTANTIATE_TEST_SUITE_P(Variants, DemodulationVsCpu,
                         ::testing::Values(std::make_tuple(FilterKind::Grid, false), std::make_tuple(FilterKind::Grid, true),
                                           std::make_tuple(FilterKind::BilateralDepth, true),
                                           std::make_tuple(FilterKind::Separable, false),
                                           std::make_tuple(FilterKind::Atrous, true),
                                           std::make_tuple(FilterKind::Subsampled, true)));

TEST(Demodulation, WithoutFilteringGivesBackTheInputs) {
  // Remodulating the demodulated inputs themselves is the identity (up to rounding), sentinels kept.
  test::osmesa_context();
  Scenario s = make_scenario(17);
  const Image albedo = albedo_image_for_test();
  GpuFixture gpu(s);
  gpu.inputs.upload_albedo(albedo);
  Demodulation demod(W, H);
  demod.demodulate(gpu.inputs, gpu.guide, FilterParams{}, test::kTestThreshold);
  demod.remodulate(demod.filter_inputs().hv(), gpu.inputs);
  // Columns 3 (black) and 5 (below the epsilon) are not demodulated: their neighbours speak for
  // them and they take their albedo's share of that, 0 in column 3 (DemodulationVsCpu checks 5).
  const Image back = demod.output().download({"R", "G", "B", "A"});
  const Image in = gpu.inputs.hv().download({"R", "G", "B", "A"});
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const size_t i = size_t(y) * W + x;
      if (x == 5) continue;
      for (int c = 0; c < 3; ++c) {
        const float want = x == 3 ? 0.0f : in.pixels[4 * i + c];
        EXPECT_NEAR(back.pixels[4 * i + c], want, 1e-6f * std::abs(want) + 1e-12f) << x << "," << y;
      }
      if (x == 3) continue;
      const float v = in.pixels[4 * i + 3], got = back.pixels[4 * i + 3];
      if (v < 0.0f || !std::isfinite(v))
        EXPECT_EQ(got, kVarUnknown) << i;
      else
        EXPECT_NEAR(got, v, 1e-6f * v) << i;
    }
  // A saturated red divides channel by channel, its nearly black blue floored at a share of its luminance.
  const float floor = shared::kChannelFloor * luminance(0.8f, 0.2f, 0.01f);
  EXPECT_EQ(shared::modulation_factor(glm::vec3(0.8f, 0.2f, 0.01f)), glm::vec3(0.8f, 0.2f, floor));
  EXPECT_EQ(shared::modulation_factor(glm::vec3(kNaN, 0.5f, 0.5f)), shared::modulation_factor(glm::vec3(0.0f, 0.5f, 0.5f)));
  EXPECT_EQ(shared::modulation_factor(glm::vec3(-1.0f)), glm::vec3(0.0f));
  // The variance of a grey factor's product scales exactly by its square.
  EXPECT_FLOAT_EQ(shared::modulated_var(2.0f, glm::vec3(0.3f, 0.1f, 0.9f), glm::vec3(0.5f)), 0.5f);
  EXPECT_EQ(shared::modulated_var(kVarUnknown, glm::vec3(1.0f), glm::vec3(0.5f)), kVarUnknown);
}

// A textured plane under constant irradiance E, seen through a guide that does not show the
// texture (a flat range color): L_u = a(x, y) E. Filtering radiance averages the texture away;
// with demodulation the filter sees the constant E and the texture, in luminance and in hue, comes
// back exactly.
// Columns 5 and 12 are strands covering a sliver of their pixels (a mean albedo below the epsilon),
// and columns 6 and 13 gaps that no surface covers (albedo 0, L_u 0), as a racquet's strings: each
// takes its coverage's share of the E filtered around it, which is again exactly its L_u.
TEST(Demodulation, TexturedConstantIrradiancePlaneKeepsItsTexture) {
  test::osmesa_context();
  const Image albedo = [] {
    Image a = Image::rgb(W, H);
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        const bool odd = ((x / 3) + (y / 3)) % 2 == 1;
        const float level = x % 7 == 6 ? 0.0f : x % 7 == 5 ? 1e-3f * kAlbedoEpsilon : 1.0f;
        const glm::vec3 color = odd ? glm::vec3(0.9f, 0.7f, 0.3f) : glm::vec3(0.03f, 0.09f, 0.18f);
        for (int c = 0; c < 3; ++c) a.at(x, y, c) = level * color[c];
      }
    return a;
  }();
  const float e[3] = {2.0f, 1.5f, 1.0f};
  Scenario s;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      for (int c = 0; c < 3; ++c) {
        s.hv.at(x, y, c) = albedo.at(x, y, c) * e[c];
        s.lv.at(x, y, c) = 0.0f;
        s.range.at(x, y, c) = 0.5f;
      }
      s.var.at(x, y, 0) = 0.01f * luminance(s.hv.at(x, y, 0), s.hv.at(x, y, 1), s.hv.at(x, y, 2));
      s.depth.at(x, y, 0) = 3.0f;
    }
  GpuFixture gpu(s);
  gpu.inputs.upload_albedo(albedo);
  for (FilterKind kind : {FilterKind::Grid, FilterKind::BilateralDepth, FilterKind::Atrous}) {
    SCOPED_TRACE(filter_kind_name(kind));
    FilterParams p;
    p.kind = kind;
    p.skip_case2 = false;
    FilterPass filter(W, H);
    filter.run(gpu.inputs, gpu.guide, p, test::kTestThreshold);
    double blurred = 0, kept = 0;
    const Image plain = filter.filtered_image();
    Demodulation demod(W, H);
    demod.demodulate(gpu.inputs, gpu.guide, p, test::kTestThreshold);
    filter.run(demod.filter_inputs(), gpu.guide, p, test::kTestThreshold);
    demod.remodulate(filter.output(), gpu.inputs);
    const Image textured = demod.filtered_image();
    for (size_t i = 0; i < s.hv.pixels.size(); ++i) {
      if (s.hv.pixels[i] == 0.0f) {  // a gap
        EXPECT_EQ(textured.pixels[i], 0.0f) << i;
        continue;
      }
      blurred = std::max(blurred, double(std::abs(plain.pixels[i] - s.hv.pixels[i]) / s.hv.pixels[i]));
      kept = std::max(kept, double(std::abs(textured.pixels[i] - s.hv.pixels[i]) / s.hv.pixels[i]));
    }
    EXPECT_GT(blurred, 0.5);  // without demodulation the checkerboard is averaged away
    EXPECT_LT(kept, 1e-5);    // with it every texel comes back
  }
}

// The à-trous luminance edge stop: on a flat guide, a step in the light itself (a shadow's edge the
// guide does not show, 1 against 0.2 with standard deviations of 0.01) stays sharp with it and is
// blurred without it; differences within sigma_l standard deviations (a ripple of 0.02 at the
// same 0.01) leave every weight as it is, so the filter is the same as without the stop there.
TEST(AtrousEdgeStop, KeepsAnEdgeOfTheLightAndLeavesTheNoiseAlone) {
  auto plane = [](auto light) {
    Scenario s;
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        for (int c = 0; c < 3; ++c) {
          s.hv.at(x, y, c) = light(x, y);
          s.lv.at(x, y, c) = 0.0f;
          s.range.at(x, y, c) = 0.5f;
        }
        s.var.at(x, y, 0) = 1e-4f;
        s.depth.at(x, y, 0) = 3.0f;
      }
    return s;
  };
  FilterParams p;
  p.kind = FilterKind::Atrous;
  p.skip_case2 = false;
  FilterParams no_stop = p;
  no_stop.sigma_l = 0.0f;
  auto filtered = [](const Scenario& s, const FilterParams& params) {
    return cpu_filter(s.hv, s.var, s.lv, s.range, s.depth, params, test::kTestThreshold).filtered;
  };
  const Scenario step = plane([](int x, int) { return x < W / 2 ? 1.0f : 0.2f; });
  double kept = 0, blurred = 0;
  const Image with_stop = filtered(step, p), without = filtered(step, no_stop);
  for (int y = 0; y < H; ++y)
    for (int x = W / 2 - 2; x < W / 2 + 2; ++x) {
      kept = std::max(kept, double(std::abs(with_stop.at(x, y, 0) - step.hv.at(x, y, 0))));
      blurred = std::max(blurred, double(std::abs(without.at(x, y, 0) - step.hv.at(x, y, 0))));
    }
  EXPECT_LT(kept, 1e-3);
  EXPECT_GT(blurred, 0.1);
  const Scenario ripple = plane([](int x, int y) { return 1.0f + 0.02f * float((x + y) % 2); });
  expect_close(filtered(ripple, p), filtered(ripple, no_stop), 1e-6f, 1e-9f, "ripple");
}

// The normal term narrows with the sharper glossy lobe of the two surfaces: 1 / s^2 times the
// diffuse exponent, s = roughness / 0.8 between 0.1 and 1.
TEST(SurfaceTerms, NormalTermNarrowsWithTheGlossyLobe) {
  const glm::vec4 a(0.0f, 0.0f, 1.0f, 1.0f), b(std::sin(0.1f), 0.0f, std::cos(0.1f), 1.0f);
  auto exponent = [&](float roughness_a, float roughness_b) {
    glm::vec4 p = a, q = b;
    p.w = roughness_a;
    q.w = roughness_b;
    return double(shared::surface_exponent(p, q, 1.0f / (0.15f * 0.15f), 0.0f));
  };
  const double rough = exponent(1.0f, 1.0f);
  EXPECT_NEAR(rough, (1.0 - std::cos(0.1)) / (0.15 * 0.15), 1e-6);
  EXPECT_NEAR(exponent(0.9f, 0.8f), rough, 1e-9);
  EXPECT_NEAR(exponent(1.0f, 0.2f) / rough, 16.0, 1e-4);  // s = 0.25: the sharper lobe decides
  EXPECT_NEAR(exponent(0.0f, 0.5f) / rough, 100.0, 1e-3);  // s at its floor, 0.1
}

// A normal-mapped plane under a directional light: its radiance varies with the shading normal
// alone (flat range color, one depth), as the path tracer sees a normal-mapped wall. With the
// normal term the filter keeps the bumps at a kernel far wider than they are; without it, it
// averages them away. Measured on the high-frequency part (the image less its 5x5 box mean)
// against the noise-free image's.
TEST(SurfaceTerms, NormalMappedPlaneKeepsItsNormalDetail) {
  test::osmesa_context();
  const glm::vec3 light = glm::normalize(glm::vec3(0.4f, 0.3f, 1.0f));
  const float two_pi = 6.28318530718f;
  std::mt19937 rng(5);
  std::normal_distribution<float> gauss(0.0f, 1.0f);
  Scenario s;
  Image clean = Image::rgb(W, H);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const glm::vec3 n = glm::normalize(glm::vec3(0.5f * std::sin(two_pi * x / 6.0f), 0.5f * std::cos(two_pi * y / 5.0f), 1.0f));
      const float radiance = 3.0f * 0.6f * std::max(glm::dot(n, light), 0.0f);
      const float noisy = radiance * (1.0f + 0.3f * gauss(rng));
      for (int c = 0; c < 3; ++c) {
        clean.at(x, y, c) = radiance;
        s.hv.at(x, y, c) = noisy;
        s.lv.at(x, y, c) = 0.0f;
        s.range.at(x, y, c) = 0.5f;
        s.surface.at(x, y, c) = n[c];
      }
      s.surface.at(x, y, 3) = 0.5f;
      s.var.at(x, y, 0) = 0.09f * radiance * radiance;
      s.depth.at(x, y, 0) = 3.0f;
    }
  auto high_pass = [](const Image& im) {
    std::vector<double> hp(im.pixel_count());
    for (int y = 0; y < im.height; ++y)
      for (int x = 0; x < im.width; ++x) {
        double sum = 0;
        int count = 0;
        for (int qy = std::max(0, y - 2); qy <= std::min(im.height - 1, y + 2); ++qy)
          for (int qx = std::max(0, x - 2); qx <= std::min(im.width - 1, x + 2); ++qx, ++count) sum += im.at(qx, qy, 1);
        hp[static_cast<size_t>(y) * im.width + x] = im.at(x, y, 1) - sum / count;
      }
    return hp;
  };
  const std::vector<double> expected = high_pass(clean);
  double expected_energy = 0;
  for (double v : expected) expected_energy += v * v;
  // The share of the noise-free detail's energy the filtered image gets wrong.
  auto detail_error = [&](const Image& filtered) {
    const std::vector<double> hp = high_pass(filtered);
    double e = 0;
    for (size_t i = 0; i < hp.size(); ++i) e += (hp[i] - expected[i]) * (hp[i] - expected[i]);
    return e / expected_energy;
  };
  // The noise-free radiance as L_u (with the noisy one's variance, so the filter does filter it):
  // what is left of its detail is the filter's blur alone.
  Scenario noiseless = s;
  noiseless.hv = clean;
  GpuFixture gpu(s), gpu_noiseless(noiseless);
  const double noisy_error = detail_error(s.hv);
  for (FilterKind kind : {FilterKind::Atrous, FilterKind::BilateralDepth, FilterKind::Separable, FilterKind::Subsampled}) {
    SCOPED_TRACE(filter_kind_name(kind));
    FilterParams p;
    p.kind = kind;
    p.sigma_s = 16.0f;
    p.skip_case2 = false;
    FilterPass filter(W, H);
    auto run = [&](const GpuFixture& in) {
      filter.run(in.inputs, in.guide, p, test::kTestThreshold, &in.surface);
      return filter.filtered_image();
    };
    const Image kept = run(gpu_noiseless), kept_noisy = run(gpu);
    expect_close(kept_noisy, cpu_filter(s.hv, s.var, s.lv, s.range, s.depth, p, test::kTestThreshold, &s.surface).filtered,
                 1e-4f, 1e-7f, "L_f");
    p.sigma_n = 0.0f;  // the normal term off
    const Image blurred = run(gpu_noiseless);
    const double kept_error = detail_error(kept), blurred_error = detail_error(blurred);
    const double noisy_kept_error = detail_error(kept_noisy);
    std::printf("%s: detail error of the noise-free plane with the normal term %.3f, without %.3f; of the noisy one "
                "%.3f unfiltered, %.3f filtered\n",
                filter_kind_name(kind), kept_error, blurred_error, noisy_error, noisy_kept_error);
    EXPECT_GT(blurred_error, 0.8);  // without the normal term the bumps are averaged away
    EXPECT_LT(kept_error, 0.1);     // with it they stay
    EXPECT_LT(noisy_kept_error, 0.6 * noisy_error);  // and the noise on them still drops
  }
}

}  // namespace
}  // namespace pxf
