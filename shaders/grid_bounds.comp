#version 450 core
// Bilateral grid, step 1: the min and max of the guide's luminance over the image (the z range of
// the grid). Each invocation scans a strip of 64 pixels of one row, then two atomics (a
// shared-memory tree with barriers costs several times more on llvmpipe).
#include "pass_formulas.h"
#include "grid_common.glsl"
layout(local_size_x = 64) in;
#include "flat_dispatch.glsl"

layout(binding = kUnitGuide) uniform sampler2D guide_tex;
const int kStrip = 64;

void main() {
  ivec2 size = textureSize(guide_tex, 0);
  int strips_per_row = (size.x + kStrip - 1) / kStrip;
  int strip = flat_invocation();
  int y = strip / strips_per_row;
  if (y >= size.y) return;
  int x0 = (strip % strips_per_row) * kStrip;
  float lo = 3.0e38, hi = 0.0;
  for (int x = x0; x < min(x0 + kStrip, size.x); ++x) {
    float l = guide_luminance(texelFetch(guide_tex, ivec2(x, y), 0));
    lo = min(lo, l);
    hi = max(hi, l);
  }
  atomicMin(y_min_bits, floatBitsToUint(lo));
  atomicMax(y_max_bits, floatBitsToUint(hi));
}
