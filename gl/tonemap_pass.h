// Tone map pass (docs/method.md section 5): Reinhard's global photographic operator with the log-average
// luminance reduced on the GPU (reduce.comp, no CPU round trip), then the sRGB curve.
// Usage:
//   TonemapPass tonemap(w, h);
//   tonemap.run(blend.output(), {});          // key 0.18, no white point
//   tonemap.output() (RGBA32F display values in [0,1]), tonemap.display_image(), last_ms()
#pragma once
#include "gl/pass_params.h"
#include "gl/reduction.h"
#include "gl/resources.h"

namespace pxf {

class TonemapPass {
 public:
  TonemapPass(int width, int height);
  void run(const Texture2D& hdr, const TonemapParams& params);
  const Texture2D& output() const { return output_; }  // rgb display values, a = 1
  float log_average() const;  // of the last run's input (read-back); params.log_average if fixed
  double last_ms() const { return timer_.last_ms(); }
  Image display_image() const;  // "R,G,B" in [0,1]

 private:
  int width_, height_;
  Program program_;
  GpuReduction reduction_;
  Texture2D output_;
  Framebuffer fbo_;
  FullscreenPass quad_;
  StageTimer timer_;
  TonemapParams last_params_;
};

}  // namespace pxf
