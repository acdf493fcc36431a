// GPU sum reduction (shaders/reduce.comp), shared by the tone map (log-average luminance) and the
// range pass (convergence, specular-pixel count).
#pragma once
#include "gl/resources.h"

namespace pxf {

// GPU sum of a texture's red channel (mode 0), of log(delta + Y(rgb)) (mode 1) or of alpha (mode 2), via two
// compute dispatches. The result stays in result_buffer() ([0] = sum, [1] = pixel count).
class GpuReduction {
 public:
  GpuReduction();
  void run(const Texture2D& source, int mode, float delta = 0.0f);
  const Buffer& result_buffer() const { return result_; }
  float read_sum() const;  // read-back (synchronizes)

 private:
  Program program_;
  Buffer partials_, result_;
};

}  // namespace pxf
