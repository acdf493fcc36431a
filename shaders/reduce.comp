#version 450 core
// Two-stage sum reduction on the GPU. Stage 0: each 16x16 work group sums one tile of the source
// texture into partial[group]; stage 1: one group sums the partials into result[0] (and writes the
// pixel count to result[1]). mode 0 sums the red channel, mode 1 log(delta + Y(rgb)), mode 2 alpha.
#include "pass_formulas.h"
layout(local_size_x = 16, local_size_y = 16) in;

layout(binding = 0) uniform sampler2D src;
uniform int stage;
uniform int mode;
uniform float delta;
uniform int partial_count;
layout(std430, binding = 1) buffer Partials { float partial[]; };
layout(std430, binding = 2) buffer Result { float result[]; };

shared float sums[256];

float value_at(ivec2 p) {
  vec4 c = texelFetch(src, p, 0);
  if (mode == 0) return clean(c.r);
  if (mode == 2) return clean(c.a);
  vec3 rgb = clamp(clean(c.rgb), vec3(0.0), vec3(kMaxInput));
  return log(delta + luminance(rgb));
}

void main() {
  uint i = gl_LocalInvocationIndex;
  float v = 0.0;
  if (stage == 0) {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = textureSize(src, 0);
    if (all(lessThan(p, size))) v = value_at(p);
  } else {
    for (int k = int(i); k < partial_count; k += 256) v += partial[k];
  }
  sums[i] = v;
  barrier();
  for (uint half_size = 128u; half_size > 0u; half_size >>= 1) {
    if (i < half_size) sums[i] += sums[i + half_size];
    barrier();
  }
  if (i != 0u) return;
  if (stage == 0) {
    partial[gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x] = sums[0];
  } else {
    ivec2 size = textureSize(src, 0);
    result[0] = sums[0];
    result[1] = float(size.x * size.y);
  }
}
