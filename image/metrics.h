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

}  // namespace pxf
