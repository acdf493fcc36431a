#version 450 core
// Bilateral grid, step 1: the min and max of the guide's luminance over the image (the z range of
// the grid). Each 16x16 group reduces its tile in shared memory, then one atomic per group.
#include "common.glsl"
#include "grid_common.glsl"
layout(local_size_x = 16, local_size_y = 16) in;

layout(binding = 2) uniform sampler2D guide_tex;

shared float lo[256];
shared float hi[256];

void main() {
  uint i = gl_LocalInvocationIndex;
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  bool inside = all(lessThan(p, textureSize(guide_tex, 0)));
  float y = inside ? guide_luminance(texelFetch(guide_tex, p, 0)) : 0.0;
  lo[i] = inside ? y : 3.0e38;
  hi[i] = y;
  barrier();
  for (uint half_size = 128u; half_size > 0u; half_size >>= 1) {
    if (i < half_size) {
      lo[i] = min(lo[i], lo[i + half_size]);
      hi[i] = max(hi[i], hi[i + half_size]);
    }
    barrier();
  }
  if (i != 0u) return;
  atomicMin(y_min_bits, floatBitsToUint(lo[0]));
  atomicMax(y_max_bits, floatBitsToUint(hi[0]));
}
