#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "image/flip.h"

using namespace pxf;

namespace {
double mean(const Image& y) {
  double s = 0;
  for (float v : y.pixels) s += v;
  return s / y.pixels.size();
}
// A mid-grey image with smooth structure, so that features and colors both matter.
Image test_pattern(int w, int h) {
  Image im = Image::rgb(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      im.at(x, y, 0) = 0.5f + 0.3f * std::sin(0.3f * x);
      im.at(x, y, 1) = 0.5f + 0.2f * std::cos(0.2f * y);
      im.at(x, y, 2) = 0.4f;
    }
  return im;
}
Image with_noise(const Image& im, float amplitude, unsigned seed) {
  Image out = im;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (float& v : out.pixels) v = std::clamp(v + amplitude * u(rng), 0.0f, 1.0f);
  return out;
}
}  // namespace

// Hand-computed: white is (100, 0, 0) and black (0, 0, 0) in CIELAB; HyAB adds |dL| to the
// Euclidean chroma distance; Hunt scales a, b by L / 100.
TEST(Flip, HyabAndHuntByHand) {
  const Lab white = flip_lab_from_linear_rgb(1, 1, 1), black = flip_lab_from_linear_rgb(0, 0, 0);
  EXPECT_NEAR(white.L, 100.0, 1e-9);
  EXPECT_NEAR(white.a, 0.0, 1e-9);
  EXPECT_NEAR(white.b, 0.0, 1e-9);
  EXPECT_NEAR(flip_hyab(white, black), 100.0, 1e-9);
  EXPECT_NEAR(flip_hyab({50, 10, 20}, {40, 13, 24}), 10.0 + 5.0, 1e-12);
  const Lab hunt = flip_hunt_adjust({50, 10, 20});
  EXPECT_NEAR(hunt.a, 5.0, 1e-12);
  EXPECT_NEAR(hunt.b, 10.0, 1e-12);
  // Green (87.7347, -86.1827, 83.1793), blue (32.2970, 79.1875, -107.8602); after Hunt:
  // |87.7347 - 32.2970| + |(-75.6122, 72.9771) - (25.5752, -34.8356)| = 203.2973.
  EXPECT_NEAR(flip_max_color_distance(), 203.2973, 1e-3);
}

// The remap: d^0.7 maps linearly to [0, 0.95] up to 0.4 cmax^0.7, then to [0.95, 1].
TEST(Flip, ColorRemapByHand) {
  const double c = std::pow(203.2973342, 0.7);
  EXPECT_EQ(flip_color_remap(0.0), 0.0);
  EXPECT_NEAR(flip_color_remap(10.0), 0.95 / (0.4 * c) * std::pow(10.0, 0.7), 1e-6);  // 0.28838
  EXPECT_NEAR(flip_color_remap(10.0), 0.28838, 1e-4);
  EXPECT_NEAR(flip_color_remap(100.0), 0.96738, 1e-4);  // 0.95 + (25.119 - 0.4 c) / (0.6 c) 0.05
  EXPECT_NEAR(flip_color_remap(std::pow(0.4 * c, 1 / 0.7)), 0.95, 1e-9);
  EXPECT_NEAR(flip_color_remap(203.2973342), 1.0, 1e-6);
  EXPECT_EQ(flip_color_remap(1e6), 1.0);
}

TEST(Flip, IdenticalImagesGiveZero) {
  const Image im = test_pattern(40, 30);
  const Image e = flip_error_map(im, im);
  for (float v : e.pixels) EXPECT_EQ(v, 0.0f);
}

// Uniform images have no features, so FLIP is the remapped color distance: 0.96738 (above).
TEST(Flip, BlackVersusWhiteIsNearOne) {
  const Image e = flip_error_map(Image::rgb(32, 32, 0.0f), Image::rgb(32, 32, 1.0f));
  for (float v : e.pixels) EXPECT_NEAR(v, 0.96738, 1e-4);
}

TEST(Flip, GrowsWithNoiseAmplitude) {
  const Image im = test_pattern(48, 48);
  double previous = 0;
  for (float amplitude : {0.01f, 0.03f, 0.1f, 0.3f}) {
    const double m = mean(flip_error_map(with_noise(im, amplitude, 7), im));
    EXPECT_GT(m, previous * 1.05) << amplitude;
    previous = m;
  }
  EXPECT_LT(previous, 1.0);
}

// The widest kernel is the CSF's, radius ceil(3 sqrt(0.04 / (2 pi^2)) 67) = 10 pixels: a change
// at one pixel reaches no further.
TEST(Flip, OnePixelChangeStaysLocal) {
  const int w = 41, h = 41, cx = 20, cy = 20, radius = 10;
  const Image ref = test_pattern(w, h);
  Image test = ref;
  for (int c = 0; c < 3; ++c) test.at(cx, cy, c) = 1.0f - ref.at(cx, cy, c);
  const Image e = flip_error_map(test, ref);
  EXPECT_GT(e.at(cx, cy, 0), 0.05f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if (std::max(std::abs(x - cx), std::abs(y - cy)) > radius) {
        EXPECT_EQ(e.at(x, y, 0), 0.0f) << x << "," << y;
      }
  EXPECT_GT(e.at(cx + radius - 2, cy, 0), 0.0f);  // the neighbourhood is affected
}

TEST(Flip, SymmetricInItsArguments) {
  const Image a = test_pattern(32, 24), b = with_noise(a, 0.2f, 3);
  const Image ab = flip_error_map(a, b), ba = flip_error_map(b, a);
  for (size_t p = 0; p < ab.pixels.size(); ++p) EXPECT_NEAR(ab.pixels[p], ba.pixels[p], 1e-6f);
}

// At fewer pixels per degree each pixel covers more of the visual field, so high-frequency noise
// is less blurred away by the CSF and FLIP rises.
TEST(Flip, PixelsPerDegreeSetsTheScale) {
  const Image a = test_pattern(40, 40), b = with_noise(a, 0.1f, 5);
  EXPECT_GT(mean(flip_error_map(b, a, 20.0)), mean(flip_error_map(b, a, 67.0)));
}

TEST(Flip, RejectsBadInput) {
  EXPECT_THROW(flip_error_map(Image::rgb(2, 2), Image::rgb(3, 2)), Error);
  EXPECT_THROW(flip_error_map(Image::gray(2, 2), Image::gray(2, 2)), Error);
  EXPECT_THROW(flip_error_map(Image::rgb(2, 2), Image::rgb(2, 2), 0.0), Error);
  Image nan = Image::rgb(4, 4, NAN);
  for (float v : flip_error_map(nan, Image::rgb(4, 4, 0.5f)).pixels) EXPECT_TRUE(std::isfinite(v));
}
