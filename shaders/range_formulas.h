// The range-buffer color formulas (docs/method.md section 1.2), computed by the raster pass's
// shaders (range.frag, range_background.frag) and by the path tracer for what it follows itself
// (the specular chains): one source, valid GLSL and C++ (shaders/cpu_gpu.h).
#include "cpu_gpu.h"

PXF_SHARED_BEGIN

// The range color of a surface: albedo times a noise-free shading term that separates differently
// oriented surfaces.
PXF_INLINE vec3 range_shading(vec3 albedo, vec3 normal, vec3 to_viewer) {
  float c = dot(normal, to_viewer);
  return albedo * (0.2f + 0.8f * (c > 0.0f ? c : 0.0f));
}

// The range color where a ray escapes to the environment: its radiance compressed to [0, 1) per
// channel by L / (1 + L), so that bright and dark parts of the environment (a softbox, the
// backdrop) differ in range color and the filter does not mix them. Non-finite radiance: black.
PXF_INLINE vec3 range_environment_color(vec3 radiance) {
  if (any(isnan(radiance)) || any(isinf(radiance))) return vec3(0.0f);
  vec3 l = max(radiance, vec3(0.0f));
  return l / (1.0f + l);
}

PXF_SHARED_END
