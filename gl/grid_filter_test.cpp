// The bilateral-grid filter (FilterKind::Grid): its Var[L_f] on white noise against the exact
// sum W^2 Var / (sum W)^2 of its effective weights, edge preservation, non-finite inputs. The GPU
// pass against the CPU reference on the shared random scenario: FilterVsCpu in passes_test.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include "core/error.h"
#include "gl/cpu_reference.h"
#include "gl/filter_pass.h"
#include "gl/grid_layout.h"
#include "gl/inputs.h"
#include "gl/test_util.h"

namespace pxf {
namespace {

// The blur tap g(d), 0 outside the taps.
double blur_tap(int d) { return std::abs(d) <= kGridBlurRadius ? kGridBlurTaps[d + kGridBlurRadius] : 0.0; }

// Effective weight, along one spatial axis, of the pixel at coordinate xi in the output at x: the
// slice's two corners, each reaching xi's nearest cell through the blur. Written from the
// definition (not from the propagation) so the test can tell the two apart.
double axis_weight(int x, int xi, float cell_s) {
  const double u = x / double(cell_s);
  const int i0 = static_cast<int>(std::floor(u));
  const double a = u - i0;
  const int c = static_cast<int>(std::floor(xi / double(cell_s) + 0.5));
  return (1 - a) * blur_tap(i0 - c) + a * blur_tap(i0 + 1 - c);
}

// sum W^2 / (sum W)^2 of the output at (x, y) on a flat guide: the exact white-noise variance factor.
double exact_variance_factor(int x, int y, int n, float cell_s) {
  double sw = 0, sw2 = 0;
  for (int yi = 0; yi < n; ++yi)
    for (int xi = 0; xi < n; ++xi) {
      const double w = axis_weight(x, xi, cell_s) * axis_weight(y, yi, cell_s);
      sw += w;
      sw2 += w * w;
    }
  return sw2 / (sw * sw);
}

// Flat guide: the grid is a fixed linear filter with weights W, white noise of variance v comes
// out with v sum W^2 / (sum W)^2 at every pixel (depending on its position within its cell).
// The propagated Var[L_f] must equal that inside the image (no border cells), and the measured
// variance over realizations must agree too. The flat region's luminance lies at fraction
// range_fraction between two range cells (one far corner pixel of lower luminance sets the grid's
// range so): every pixel then reaches both interpolated range cells through the blur, a factor
// common to all weights, so the exact variance factor is the same, and the propagated one must
// still match it (grid_range_correction; without it, 0.56x at 1/2).
void expect_white_noise_variance_matches_exact_sum(float range_fraction) {
  SCOPED_TRACE(testing::Message() << "range fraction " << range_fraction);
  test::osmesa_context();
  constexpr int N = 160;
  constexpr float kNoiseVar = 1.0f / 3.0f;  // uniform in [0, 2]
  Image lv = Image::rgb(N, N), var = Image::gray(N, N, "Y", kNoiseVar), guide = Image::rgba(N, N, 0.5f);
  // The corner's luminance sets Y_min: the flat region then sits at z = 1 + range_fraction.
  for (int c = 0; c < 3; ++c) guide.at(0, 0, c) = 0.5f - (1.0f + range_fraction) * grid_min_cell_z(FilterParams{}.sigma_c);
  PreviewInputs inputs(N, N);
  Texture2D guide_tex(N, N, TextureFormat::RGBA32F);
  guide_tex.upload(guide);
  FilterPass filter(N, N);
  FilterParams p;
  p.kind = FilterKind::Grid;
  p.sigma_s = 8.0f / kGridCellPerSigma;  // cells of 8 px
  const float cell_s = grid_layout(N, N, p).cell_s;
  ASSERT_EQ(cell_s, 8.0f);
  p.skip_case2 = false;
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> noise(0.0f, 2.0f);
  // Output pixels at cell fractions 0, 1/4, 1/2, 3/4 in x and y, far from the border.
  const int xs[] = {64, 66, 68, 70};
  double sum_sq[4][4] = {}, propagated[4][4] = {};
  constexpr int kRealizations = 120;
  for (int r = 0; r < kRealizations; ++r) {
    Image hv = Image::rgb(N, N);
    for (float& v : hv.pixels) v = noise(rng);
    inputs.upload(lv, hv, var);
    filter.run(inputs, guide_tex, p, test::kTestThreshold);
    Image f = filter.filtered_image(), v = filter.raw_variance_image();
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i) {
        // The same position within a cell recurs every 8 px: average over 8 x 8 such pixels.
        for (int cy = -4; cy < 4; ++cy)
          for (int cx = -4; cx < 4; ++cx) {
            const double d = f.at(xs[i] + 8 * cx, xs[j] + 8 * cy, 0) - 1.0;
            sum_sq[j][i] += d * d / 64;
          }
        propagated[j][i] = v.at(xs[i], xs[j], 0) / kNoiseVar;
      }
  }
  const Image centre = filter.centre_weight_image();
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) {
      const double exact = exact_variance_factor(xs[i], xs[j], N, cell_s);
      const double measured = sum_sq[j][i] / kRealizations / kNoiseVar;
      const double uncorrected = propagated[j][i] / (grid_interpolation_correction((xs[i] % 8) / 8.0f) *
                                                     grid_interpolation_correction((xs[j] % 8) / 8.0f));
      std::printf("pixel (%d, %d): variance x %.4g exact, x %.4g measured, Var[L_f] x %.4g (without the spatial corrections %.4g)\n",
                  xs[i], xs[j], exact, measured, propagated[j][i], uncorrected);
      EXPECT_NEAR(propagated[j][i] / exact, 1.0, 1e-3) << xs[i] << ", " << xs[j];
      EXPECT_NEAR(measured / exact, 1.0, 0.1) << xs[i] << ", " << xs[j];
      // The centre weight (the blend's covariance term): the pixel's own effective weight over the
      // sum, from the definition; on a flat guide the range axis contributes the same factor to both.
      double own = axis_weight(xs[i], xs[i], cell_s) * axis_weight(xs[j], xs[j], cell_s), sx = 0, sy = 0;
      for (int k = 0; k < N; ++k) sx += axis_weight(xs[i], k, cell_s), sy += axis_weight(xs[j], k, cell_s);
      ASSERT_NE(filter.centre_weight(), nullptr);
      EXPECT_NEAR(centre.at(xs[i], xs[j], 0) / (own / (sx * sy)), 1.0, 1e-4) << xs[i] << ", " << xs[j];
      if (i == 2 && j == 2 && range_fraction == 0.0f) {
        EXPECT_GT(exact / uncorrected, 2.5) << "the correction matters at the cell boundary";
      }
    }
}
}  // namespace

TEST(Grid, WhiteNoiseVarianceMatchesExactSum) {
  for (const float range_fraction : {0.0f, 0.5f, 0.3f}) expect_white_noise_variance_matches_exact_sum(range_fraction);
}

namespace {

TEST(Grid, LuminanceEdgesArePreserved) {
  // Steps in the range color's luminance (the grid's range axis), constant HV on each side: no
  // mixing across, even where the luminances differ by only 5 sigma_c.
  test::osmesa_context();
  constexpr int W = 61, H = 45;
  Image lv = Image::rgb(W, H), hv = Image::rgb(W, H), var = Image::gray(W, H, "Y", 0.5f), guide = Image::rgba(W, H);
  auto region = [](int x, int y) { return (x < W / 2 ? 0 : 1) + (y < H / 2 ? 0 : 2); };
  const float range_y[4] = {0.8f, 0.1f, 0.2f, 0.5f}, value[4] = {1.0f, 3.0f, 2.0f, 7.0f};
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      for (int c = 0; c < 3; ++c) {
        guide.at(x, y, c) = range_y[region(x, y)];
        hv.at(x, y, c) = value[region(x, y)];
      }
      guide.at(x, y, 3) = 3.0f;
    }
  PreviewInputs inputs(W, H);
  inputs.upload(lv, hv, var);
  Texture2D guide_tex(W, H, TextureFormat::RGBA32F);
  guide_tex.upload(guide);
  FilterPass filter(W, H);
  FilterParams p;
  p.kind = FilterKind::Grid;
  p.skip_case2 = false;
  filter.run(inputs, guide_tex, p, test::kTestThreshold);
  Image f = filter.filtered_image();
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) ASSERT_NEAR(f.at(x, y, 0), value[region(x, y)], 1e-5f) << x << ", " << y;
}

TEST(Grid, NonFiniteInputsGiveFiniteOutput) {
  // NaN, infinities and huge values in HV, variance and guide: finite L_f and Var[L_f] (or a
  // sentinel) everywhere, as the CPU reference computes them.
  test::osmesa_context();
  constexpr int W = 23, H = 19;
  constexpr float kNaN = std::numeric_limits<float>::quiet_NaN(), kInf = std::numeric_limits<float>::infinity();
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u01(0.0f, 1.0f);
  Image lv = Image::rgb(W, H), hv = Image::rgb(W, H), var = Image::gray(W, H), range = Image::rgb(W, H),
        depth = Image::gray(W, H), guide = Image::rgba(W, H);
  for (float& v : lv.pixels) v = 0.1f * u01(rng);
  for (float& v : hv.pixels) v = u01(rng);
  for (float& v : var.pixels) v = 0.01f * u01(rng);
  for (float& v : range.pixels) v = u01(rng);
  for (float& v : depth.pixels) v = 1.0f + u01(rng);
  hv.at(1, 1, 0) = kNaN;
  hv.at(2, 1, 1) = kInf;
  hv.at(3, 1, 2) = 1e30f;
  var.at(4, 1, 0) = kNaN;
  var.at(5, 1, 0) = kInf;
  var.at(6, 1, 0) = 1e30f;
  range.at(7, 1, 0) = kNaN;
  range.at(8, 1, 1) = kInf;
  range.at(9, 1, 2) = -kInf;
  depth.at(10, 1, 0) = kNaN;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      for (int c = 0; c < 3; ++c) guide.at(x, y, c) = range.at(x, y, c);
      guide.at(x, y, 3) = depth.at(x, y, 0);
    }
  PreviewInputs inputs(W, H);
  inputs.upload(lv, hv, var);
  Texture2D guide_tex(W, H, TextureFormat::RGBA32F);
  guide_tex.upload(guide);
  FilterPass filter(W, H);
  for (bool skip : {false, true}) {
    FilterParams p;
    p.kind = FilterKind::Grid;
    p.skip_case2 = skip;
    const float t = 0.05f;
    filter.run(inputs, guide_tex, p, t);
    FilterOutput ref = cpu_filter(hv, var, lv, range, depth, p, t);
    Image f = filter.filtered_image(), v = filter.raw_variance_image();
    for (size_t i = 0; i < f.pixels.size(); ++i) {
      ASSERT_TRUE(std::isfinite(f.pixels[i])) << i;
      ASSERT_TRUE(std::isfinite(ref.filtered.pixels[i])) << i;
      EXPECT_NEAR(f.pixels[i], ref.filtered.pixels[i], 1e-4f * std::abs(ref.filtered.pixels[i]) + 1e-6f) << i;
    }
    for (size_t i = 0; i < v.pixels.size(); ++i) {
      ASSERT_TRUE(std::isfinite(v.pixels[i])) << i;
      EXPECT_NEAR(v.pixels[i], ref.variance.pixels[i], 1e-4f * std::abs(ref.variance.pixels[i]) + 1e-12f) << i;
    }
  }
}

// Random inputs of one size for the stepped-run test: L_lv, L_u, Var[L_u], and a guide.
struct RandomFilterInputs {
  PreviewInputs inputs;
  Texture2D guide;
  RandomFilterInputs(int w, int h, unsigned seed) : inputs(w, h), guide(w, h, TextureFormat::RGBA32F) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u01(0.0f, 1.0f);
    Image lv = Image::rgb(w, h), hv = Image::rgb(w, h), var = Image::gray(w, h), g = Image::rgba(w, h);
    for (float& v : lv.pixels) v = 0.05f * u01(rng);
    for (float& v : hv.pixels) v = u01(rng);
    for (float& v : var.pixels) v = 0.02f * u01(rng);
    for (float& v : g.pixels) v = 0.2f + u01(rng);
    inputs.upload(lv, hv, var);
    guide.upload(g);
  }
};

// A run in steps (FilterPass::begin/step, for the explorer's frame budget) gives the very run of
// FilterPass::run, even when other filter runs, with their own grid, bounds and counter buffers
// bound at the same binding points, happen between its steps; until its last step the output is
// the previous run's.
TEST(Grid, ARunInStepsWithOtherRunsBetweenEqualsOneRun) {
  test::osmesa_context();
  constexpr int W = 61, H = 47;
  RandomFilterInputs a(W, H, 11), b(W, H, 12);
  FilterParams p;
  p.kind = FilterKind::Grid;
  const float t = 0.1f;
  FilterPass whole(W, H), stepped(W, H), other(W, H);
  whole.run(a.inputs, a.guide, p, t);
  stepped.run(b.inputs, b.guide, p, t);  // a previous run, of other inputs
  const Image previous = stepped.filtered_image();

  EXPECT_THROW(other.step(), Error);  // no run begun
  stepped.begin(a.inputs, a.guide, p, t);
  int steps = 0;
  FilterParams other_params = p;
  other_params.sigma_s *= 2.0f;
  while (true) {
    ASSERT_TRUE(stepped.in_progress());
    const bool done = stepped.step();
    ++steps;
    if (done) break;
    EXPECT_EQ(stepped.filtered_image().pixels, previous.pixels) << "the output changed before the run's last step";
    other.run(b.inputs, b.guide, other_params, 0.5f * t);  // rebinds every buffer and texture unit
  }
  EXPECT_EQ(steps, GridFilter::kSteps);
  EXPECT_FALSE(stepped.in_progress());
  EXPECT_THROW(stepped.step(), Error);
  EXPECT_EQ(stepped.filtered_image().pixels, whole.filtered_image().pixels);
  EXPECT_EQ(stepped.raw_variance_image().pixels, whole.raw_variance_image().pixels);
  EXPECT_EQ(stepped.centre_weight_image().pixels, whole.centre_weight_image().pixels);
  EXPECT_EQ(stepped.filtered_pixels(), whole.filtered_pixels());
  EXPECT_GT(whole.filtered_pixels(), 0u);
  EXPECT_NE(whole.filtered_pixels(), static_cast<uint32_t>(W * H)) << "the skip should leave some pixels";

  // The other variants are one step.
  p.kind = FilterKind::Atrous;
  stepped.begin(a.inputs, a.guide, p, t);
  EXPECT_TRUE(stepped.step());
  whole.run(a.inputs, a.guide, p, t);
  EXPECT_EQ(stepped.filtered_image().pixels, whole.filtered_image().pixels);
}

}  // namespace
}  // namespace pxf
