#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "image/flip.h"
#include "image/metrics.h"
#include "image/tonemap.h"

using namespace pxf;

namespace {
Image gradient(int w, int h, float scale) {
  Image im = Image::rgb(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) im.at(x, y, c) = scale * (0.1f + 0.05f * x + 0.02f * y + 0.1f * c);
  return im;
}
}  // namespace

TEST(MaskedMetrics, MaskedPixelsAreLeftOut) {
  Image ref = Image::rgb(2, 1, 1.0f), test = Image::rgb(2, 1, 1.0f);
  for (int c = 0; c < 3; ++c) test.at(1, 0, c) = 5.0f;  // wrong only at the masked pixel
  Image mask = Image::gray(2, 1, "emitter");
  mask.at(1, 0, 0) = 0.25f;
  EXPECT_GT(compare_images(test, ref).rmse, 1.0);
  const ImageMetrics m = compare_images(test, ref, &mask);
  EXPECT_EQ(m.samples, 3u);
  EXPECT_EQ(m.rmse, 0.0);
  EXPECT_THROW(compare_images(test, ref, &static_cast<const Image&>(Image::gray(3, 1))), Error);
}

// A reference without one finite sample cannot judge anything: an error, not NRMSE 0.
TEST(MaskedMetrics, AllNonFiniteReferenceIsAnError) {
  EXPECT_THROW(compare_images(Image::rgb(3, 2, 1.0f), Image::rgb(3, 2, NAN)), Error);
  EXPECT_THROW(compare_images(Image::rgb(3, 2, 1.0f), Image::rgb(3, 2, INFINITY)), Error);
  Image partly = Image::rgb(3, 2, 1.0f);
  partly.at(0, 0, 0) = NAN;
  EXPECT_EQ(compare_images(Image::rgb(3, 2, 1.0f), partly).reference_nonfinite, 1u);
}

// The display NRMSE is the NRMSE of both images through the product's tone map with the
// reference's log-average luminance, so a test twice as bright shows its error on screen.
TEST(DisplayMetrics, UsesTheReferencesToneMap) {
  const Image ref = gradient(16, 8, 1.0f), brighter = gradient(16, 8, 2.0f);
  TonemapParams p;
  p.log_average = static_cast<float>(log_average_luminance(ref, p.delta));
  const double expected = compare_images(tonemap_reinhard(brighter, p), tonemap_reinhard(ref, p)).nrmse_percent;
  const DisplayMetrics m = compare_display(brighter, ref);
  EXPECT_NEAR(m.display_nrmse_percent, expected, 1e-9);
  EXPECT_GT(m.display_nrmse_percent, 5.0);  // tone-mapping each with its own average would hide it
  EXPECT_EQ(m.hdr.nrmse_percent, compare_images(brighter, ref).nrmse_percent);
  EXPECT_GT(m.flip_mean, 0.0);
  const DisplayMetrics same = compare_display(ref, ref);
  EXPECT_EQ(same.display_nrmse_percent, 0.0);
  EXPECT_EQ(same.flip_mean, 0.0);
}

// The display tone map stays finite for any finite image and shows a bright pixel white: where k Y
// overflowed (a small fixed log-average) or lm / white^2 did, the factor was 0 (black) or NaN.
TEST(Tonemap, AnyFiniteImageGivesFiniteDisplayValuesAndBrightPixelsWhite) {
  Image hdr = Image::rgb(4, 1, 0.0f);
  const float values[4] = {1e30f, 3.4e38f, 1e-30f, 0.0f};
  for (int x = 0; x < 4; ++x)
    for (int c = 0; c < 3; ++c) hdr.at(x, 0, c) = values[x];
  hdr.at(3, 0, 0) = 1e30f;  // a red pixel: green and blue stay 0, never 0 times an infinite factor
  for (float log_average : {0.0f, 1e-20f, 1e-4f, 1e30f})
    for (float white : {0.0f, 1e-3f, 1e-20f, 4.0f}) {
      TonemapParams p;
      p.log_average = log_average;
      p.white = white;
      const Image d = tonemap_reinhard(hdr, p);
      const std::string what = "log_average " + std::to_string(log_average) + ", white " + std::to_string(white);
      EXPECT_EQ(count_nonfinite(d), 0u) << what;
      for (float v : d.pixels) EXPECT_TRUE(v >= 0.0f && v <= 1.0f) << what;
      if (log_average == 1e30f) continue;  // the image's own brightness: mid-grey, not white
      EXPECT_FLOAT_EQ(d.at(0, 0, 0), 1.0f) << what;
      EXPECT_FLOAT_EQ(d.at(1, 0, 1), 1.0f) << what;
      EXPECT_FLOAT_EQ(d.at(3, 0, 0), 1.0f) << what;
      EXPECT_EQ(d.at(3, 0, 1), 0.0f) << what;
    }
}

// The masked FLIP mean averages the FLIP map over the kept pixels only.
TEST(DisplayMetrics, MaskAppliesToEveryMetric) {
  const Image ref = gradient(24, 24, 1.0f);
  Image test = ref;
  for (int c = 0; c < 3; ++c) test.at(2, 2, c) = 50.0f;  // a "light" that differs
  Image mask = Image::gray(24, 24, "emitter");
  mask.at(2, 2, 0) = 1.0f;
  const DisplayMetrics all = compare_display(test, ref), masked = compare_display(test, ref, &mask);
  EXPECT_GT(all.hdr.nrmse_percent, 10 * masked.hdr.nrmse_percent);
  EXPECT_EQ(masked.hdr.rmse, 0.0);
  EXPECT_EQ(masked.display_nrmse_percent, 0.0);
  const DisplayImages d = tonemap_like_reference(test, ref);
  const Image flip = flip_error_map(d.test, d.reference);
  double sum = 0;
  for (size_t p = 0; p < flip.pixels.size(); ++p) sum += p == 2 * 24 + 2 ? 0.0 : flip.pixels[p];
  EXPECT_NEAR(masked.flip_mean, sum / (flip.pixels.size() - 1), 1e-9);
  EXPECT_LT(masked.flip_mean, all.flip_mean);
}

// Outliers: Y(test) > 5 x max(Y(reference), 0.01 x mean Y(reference)), counted by hand on a 4x1 image.
TEST(OutlierMetrics, CountsPixelsAboveFiveTimesTheReference) {
  Image ref = Image::rgb(4, 1, 1.0f), test = Image::rgb(4, 1, 1.0f);
  for (int c = 0; c < 3; ++c) {
    test.at(0, 0, c) = 4.99f;  // below 5x: kept
    test.at(1, 0, c) = 5.01f;  // above 5x: an outlier
    ref.at(2, 0, c) = 0.0f;    // a black reference pixel: judged against the floor
    test.at(2, 0, c) = 0.04f;  // floor = 0.01 x mean(1, 1, 0, 1) = 0.0075; 5 x floor = 0.0375 < 0.04
  }
  const OutlierMetrics m = count_outliers(test, ref);
  EXPECT_EQ(m.pixels, 4u);
  EXPECT_EQ(m.outliers, 2u);
  EXPECT_DOUBLE_EQ(m.fraction, 0.5);
  EXPECT_NEAR(m.luminance_floor, 0.0075, 1e-7);
  std::vector<size_t> where{7};
  count_outliers(test, ref, nullptr, {}, &where);
  EXPECT_EQ(where, (std::vector<size_t>{1, 2}));
  for (int c = 0; c < 3; ++c) test.at(2, 0, c) = 0.035f;  // under 5 x floor: no longer an outlier
  EXPECT_EQ(count_outliers(test, ref).outliers, 1u);
  OutlierOptions looser;
  looser.factor = 6.0;
  EXPECT_EQ(count_outliers(test, ref, nullptr, looser).outliers, 0u);
  EXPECT_EQ(count_outliers(ref, ref).outliers, 0u);
}

// Luminance, not a channel: a pure-blue pixel of 10 is no outlier against grey 1 (Y 0.72 < 5), but
// is one against a pure-blue reference of 1 (Y 0.72 > 5 x 0.072).
TEST(OutlierMetrics, UsesLuminance) {
  Image grey = Image::rgb(1, 1, 1.0f), test = Image::rgb(1, 1, 0.0f);
  test.at(0, 0, 2) = 10.0f;  // Y = 0.722 < 5 x 1
  EXPECT_EQ(count_outliers(test, grey).outliers, 0u);
  Image blue = Image::rgb(1, 1, 0.0f);
  blue.at(0, 0, 2) = 1.0f;  // Y = 0.0722, 5x = 0.361
  EXPECT_EQ(count_outliers(test, blue).outliers, 1u);
}

// A non-finite test pixel is an outlier; a non-finite reference pixel and masked pixels are not judged.
TEST(OutlierMetrics, NonFiniteAndMask) {
  Image ref = Image::rgb(3, 1, 1.0f), test = Image::rgb(3, 1, 1.0f);
  test.at(0, 0, 1) = NAN;
  ref.at(1, 0, 0) = INFINITY;
  test.at(2, 0, 0) = 100.0f;
  OutlierMetrics m = count_outliers(test, ref);
  EXPECT_EQ(m.pixels, 2u);
  EXPECT_EQ(m.outliers, 2u);
  Image mask = Image::gray(3, 1, "emitter");
  mask.at(2, 0, 0) = 1.0f;
  m = count_outliers(test, ref, &mask);
  EXPECT_EQ(m.pixels, 1u);
  EXPECT_EQ(m.outliers, 1u);
  EXPECT_THROW(count_outliers(test, Image::rgb(2, 1, 1.0f)), Error);
  EXPECT_THROW(count_outliers(Image::gray(3, 1), ref), Error);
  EXPECT_EQ(count_outliers(test, Image::rgb(3, 1, NAN)).pixels, 0u);
}

// The squared error per pixel, the share of its worst pixels and of a mask's pixels.
TEST(ErrorConcentration, WorstPixelsAndMaskShares) {
  Image reference = Image::rgb(10, 10, 1.0f), test = reference;
  for (int i = 0; i < 100; ++i) test.at(i % 10, i / 10, 0) += 0.1f;  // noise spread evenly: 0.01 per pixel
  test.at(3, 4, 1) += 3.0f;                                          // one firefly: 9
  test.at(5, 5, 2) = NAN;                                            // left out
  const std::vector<double> e = pixel_squared_errors(test, reference);
  ASSERT_EQ(e.size(), 100u);
  EXPECT_NEAR(e[4 * 10 + 3], 9.01, 1e-5);
  EXPECT_NEAR(e[5 * 10 + 5], 0.01, 1e-6);
  EXPECT_NEAR(total_squared_error(e), 10.0, 1e-4);
  EXPECT_NEAR(worst_pixels_share(e, 0.01), 0.901, 1e-5);         // the firefly's pixel
  EXPECT_NEAR(worst_pixels_share(e, 0.02), 0.902, 1e-5);         // and one more
  EXPECT_NEAR(worst_pixels_share(e, 0.001), 0.901, 1e-5);        // at least one pixel
  EXPECT_NEAR(worst_pixels_share(e, 1.0), 1.0, 1e-12);
  EXPECT_EQ(worst_pixels_share(pixel_squared_errors(reference, reference), 0.01), 0.0);
  Image mask = Image::gray(10, 10);
  mask.at(3, 4, 0) = 0.25f;
  mask.at(0, 0, 0) = 1.0f;
  EXPECT_NEAR(masked_squared_error(e, mask), 9.02, 1e-5);
  EXPECT_THROW(masked_squared_error(e, Image::gray(5, 5)), Error);
}

// Two noisy references of one truth recover the test's error against the truth: the raw NRMSE
// against one reference carries that reference's noise too (here 40 % more than the true error),
// the corrected one does not, in HDR and (to first order) in display values.
TEST(ReferenceNoise, TwoReferencesRecoverTheErrorAgainstTheTruth) {
  const Image truth = gradient(96, 64, 1.0f);
  std::mt19937 rng(7);
  std::normal_distribution<float> normal(0.0f, 1.0f);
  auto noisy = [&](float relative_sd, float gain) {
    Image im = truth;
    for (float& v : im.pixels) v = gain * v * (1.0f + relative_sd * normal(rng));
    return im;
  };
  const Image reference = noisy(0.05f, 1.0f), second = noisy(0.05f, 1.0f), test = noisy(0.04f, 1.02f);
  const DisplayMetrics raw = compare_display(test, reference), references = compare_display(second, reference);
  const DisplayMetrics exact = compare_display(test, truth);
  const ReferenceNoiseCorrection hdr =
      correct_for_reference_noise(raw.hdr.nrmse_percent, references.hdr.nrmse_percent);
  const ReferenceNoiseCorrection display =
      correct_for_reference_noise(raw.display_nrmse_percent, references.display_nrmse_percent);
  EXPECT_GT(raw.hdr.nrmse_percent, 1.3 * exact.hdr.nrmse_percent);
  EXPECT_NEAR(hdr.corrected_percent, exact.hdr.nrmse_percent, 0.04 * exact.hdr.nrmse_percent);
  EXPECT_NEAR(hdr.reference_noise_percent, compare_images(reference, truth).nrmse_percent,
              0.04 * hdr.reference_noise_percent);
  EXPECT_GT(raw.display_nrmse_percent, 1.3 * exact.display_nrmse_percent);
  EXPECT_NEAR(display.corrected_percent, exact.display_nrmse_percent, 0.06 * exact.display_nrmse_percent);
  EXPECT_FALSE(hdr.within_reference_noise);
}

// An error the reference's noise explains is reported as such, never as a NaN.
TEST(ReferenceNoise, WithinTheNoiseIsZero) {
  const ReferenceNoiseCorrection c = correct_for_reference_noise(1.0, 2.0);  // 1 < 2^2 / 2
  EXPECT_TRUE(c.within_reference_noise);
  EXPECT_EQ(c.corrected_percent, 0.0);
  EXPECT_NEAR(c.reference_noise_percent, std::sqrt(2.0), 1e-12);
  const ReferenceNoiseCorrection exact = correct_for_reference_noise(5.0, std::sqrt(2.0) * 3.0);
  EXPECT_NEAR(exact.corrected_percent, 4.0, 1e-12);
  EXPECT_FALSE(exact.within_reference_noise);
}
