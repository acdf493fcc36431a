// What the explorer's pixel inspector shows of one pixel: the buffers there and the blend's
// decision as the last blend run made it (BlendPass::inspect: the shared blend_pixel on the texels
// the pass read, so pooled u, t_n, s, f and the case are the ones the image was made with), and the
// material under it with its BSDF's lobes. GL only, no ImGui, so it can be tested headless.
#pragma once
#include <cstdint>
#include <vector>

#include "gl/blend_pass.h"
#include "preview/preview.h"

namespace pxf {

struct PixelProbe {
  int x = -1, y = -1;
  uint32_t n = 0;           // paths traced into the pixel
  glm::vec4 final_s{0.0f};  // the blend's output: rgb L, a s
  glm::vec4 guide{0.0f};    // the range buffer: rgb range color, a distance
  bool blended = false;     // the blend has run (else `blend` is empty)
  BlendInspection blend;    // L_u, L_lv, L_f and their variances, the run's switches and the decision
  SurfaceMaterial surface;  // the material the pixel's centre ray meets first, and its lobes
};

// `samples`: the paths per pixel (a snapshot of Preview::pixel_samples(), row-major); 0 outside it.
PixelProbe probe_pixel(const Preview& preview, const std::vector<uint32_t>& samples, int x, int y);

}  // namespace pxf
