// The display transform, computed by the tone-map pass (tonemap.frag) and by image/tonemap.cpp
// (the metrics' display values and the CPU reference of the pass): one source, valid GLSL and C++
// (shaders/cpu_gpu.h).
#include "cpu_gpu.h"

PXF_SHARED_BEGIN

// The sRGB transfer curve of a linear value in [0,1]; NaN and values <= 0 give 0.
PXF_INLINE float srgb_encode(float v) {
  if (!(v > 0.0f)) return 0.0f;
  return v <= 0.0031308f ? 12.92f * v : 1.055f * pow(v, 1.0f / 2.4f) - 0.055f;
}

// Reinhard's global photographic operator as a factor on the pixel's color: Ld / Y for the
// luminance y and the key-scaled luminance lm = k y, with the white point `white` (in key-scaled
// luminance; <= 0: none), written k (1 + lm / white^2) / (1 + lm) so that nothing divides by y.
// Finite for every finite input: where k y or lm / white^2 overflows (a bright pixel under a small
// log-average or white point; k (1 + Inf) / (1 + Inf) was NaN, k / (1 + Inf) black) the same
// factor is formed without them, 1 / (1/k + y) (1 + y k / white^2); and it is at most 3e38, so
// that a zero channel times it stays 0.
PXF_INLINE float reinhard_scale(float k, float y, float white) {
  float lm = k * y;
  float w2 = max(white * white, 1.0e-37f);  // a white point so small that its square underflows: 0 / 0
  float burn = white > 0.0f ? 1.0f + lm / w2 : 1.0f;
  float scale = k * burn / (1.0f + lm);
  if (isinf(lm) || isinf(burn) || isinf(scale) || isnan(scale)) {
    float a = 1.0f / (1.0f / k + y);  // k / (1 + k y), with no k y
    scale = a + (white > 0.0f ? y * a / w2 : 0.0f);
  }
  return min(scale, 3.0e38f);
}

PXF_SHARED_END
