// Display-space metrics beside the HDR ones of compare_images (image/image.h): what the user sees
// is the tone-mapped image, so both images are tone-mapped with the reference's Reinhard key and
// log-average luminance (the product's tone map, image/tonemap.h) and compared as sRGB-encoded
// display values in [0,1].
#pragma once
#include "image/flip.h"
#include "image/image.h"

namespace pxf {

struct DisplayImages {
  Image test, reference;  // "R,G,B" sRGB-encoded in [0,1]
};
// Both "R,G,B" images tone-mapped with the reference's log-average luminance and the given key.
DisplayImages tonemap_like_reference(const Image& test, const Image& reference, float key = 0.18f);

struct DisplayMetricOptions {
  float key = 0.18f;  // the product's default Reinhard key
  double pixels_per_degree = kFlipDefaultPpd;
};
struct DisplayMetrics {
  ImageMetrics hdr;                  // compare_images on the linear HDR values
  double display_nrmse_percent = 0;  // NRMSE (% of the reference's mean) of the sRGB display values
  double flip_mean = 0;              // mean LDR-FLIP of the display images, in [0,1]
};
// All three metrics over the pixels the mask keeps (mask > 0 is left out; null: every pixel). The
// images need R,G,B channels. Throws pxf::Error like compare_images.
DisplayMetrics compare_display(const Image& test, const Image& reference, const Image* mask = nullptr,
                               const DisplayMetricOptions& options = {});

// A reference renders noise of its own, and that noise adds to every error measured against it:
// two references of different seeds at a few thousand spp can differ by as much as a filtered
// short job's whole error. With a second reference R2 rendered like the first
// R1 (same sample count and settings, another seed), the test's error against the truth follows:
//   E[NRMSE(test, R1)^2] = NRMSE(test, truth)^2 + noise(R1)^2   (independent noise adds in MSE)
//   E[NRMSE(R2, R1)^2]   = 2 noise(R1)^2                        (R2's noise is R1's in law)
// so NRMSE(test, truth)^2 is estimated by NRMSE(test, R1)^2 - NRMSE(R2, R1)^2 / 2, each NRMSE
// against R1 (its mean, and in display values its tone map). Unbiased in the MSE for HDR values;
// for display values only to first order in the reference's noise (the tone map is smooth).
struct ReferenceNoiseCorrection {
  double reference_noise_percent = 0;  // noise(R1): NRMSE(R2, R1) / sqrt(2)
  double corrected_percent = 0;        // the estimate of NRMSE(test, truth); 0 within the noise
  bool within_reference_noise = false; // NRMSE(test, R1)^2 <= noise(R1)^2: no error can be told
};
ReferenceNoiseCorrection correct_for_reference_noise(double test_nrmse_percent, double references_nrmse_percent);

// Fireflies: pixels whose luminance is above `factor` times the reference's luminance there. Where
// the reference is dark the bound would catch any noise, so the reference luminance is floored at
// floor_fraction times the reference image's mean luminance: a pixel is an outlier when
// Y(test) > factor * max(Y(reference), floor_fraction * mean Y(reference)). A test pixel that is NaN
// or Inf counts as an outlier; pixels whose reference is not finite, or that the mask leaves out
// (mask > 0), are not counted at all. Needs R,G,B in both; throws pxf::Error like compare_images.
struct OutlierOptions {
  double factor = 5.0;
  double floor_fraction = 0.01;
};
struct OutlierMetrics {
  size_t outliers = 0;
  size_t pixels = 0;        // pixels judged
  double fraction = 0;      // outliers / pixels (0 when no pixel was judged)
  double luminance_floor = 0;  // floor_fraction * the reference's mean luminance over the judged pixels
};
// `where`, when given, receives the outlier pixels' indices (y * width + x), ascending.
OutlierMetrics count_outliers(const Image& test, const Image& reference, const Image* mask = nullptr,
                              const OutlierOptions& options = {}, std::vector<size_t>* where = nullptr);

// Where the squared error sits. Per pixel, |test - reference|^2 summed over the shared color
// channels (non-finite samples left out, as compare_images does).
std::vector<double> pixel_squared_errors(const Image& test, const Image& reference);
// The share of the summed squared error carried by the ceil(fraction * pixels) pixels with the
// largest errors: near `fraction` for noise spread evenly, near 1 for a few fireflies. 0 without error.
double worst_pixels_share(std::vector<double> squared_errors, double fraction);
// The summed squared error of the pixels the mask selects (mask > 0; a mask, like the emitter
// layer, whose pixels are the ones of interest), and of all pixels.
double masked_squared_error(const std::vector<double>& squared_errors, const Image& mask);
double total_squared_error(const std::vector<double>& squared_errors);

}  // namespace pxf
