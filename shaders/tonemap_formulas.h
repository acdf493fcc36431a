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
// key-scaled luminance lm = k Y, with the white point `white` (in key-scaled luminance; <= 0:
// none), written k (1 + lm / white^2) / (1 + lm) so that nothing divides by Y.
PXF_INLINE float reinhard_scale(float k, float lm, float white) {
  float burn = white > 0.0f ? 1.0f + lm / (white * white) : 1.0f;
  return k * burn / (1.0f + lm);
}

PXF_SHARED_END
