// The plain CPU form of the display tone map: Reinhard's global operator on the log-average
// luminance, then sRGB encoding. One formula for the GL pass's CPU reference (gl/cpu_reference)
// and for the display-space metrics (image/metrics), so both judge what the user sees.
#pragma once
#include "image/image.h"

namespace pxf {

struct TonemapParams {
  float key = 0.18f;         // Reinhard's key a
  float white = 0.0f;        // white point in key-scaled luminance; 0 = none (L/(1+L))
  float log_average = 0.0f;  // > 0: use this log-average luminance instead of the image's
  float delta = 1.0e-4f;     // log-average offset: exp(mean(log(delta + Y)))
};

// Inputs larger than this are clamped, so that sums over a whole image stay finite in float.
constexpr float kMaxTonemapInput = 1.0e30f;

// exp(mean(log(delta + Y))) over the pixels of "R,G,B" (channels 0..2); non-finite and negative
// values read as 0.
double log_average_luminance(const Image& rgb, float delta);
// "R,G,B" sRGB-encoded display values in [0,1].
Image tonemap_reinhard(const Image& rgb, const TonemapParams& params);

}  // namespace pxf
