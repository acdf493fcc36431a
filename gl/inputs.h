// The per-frame inputs of the filter and blend passes, as persistent GL textures: one upload per
// buffer per frame (glTextureSubImage2D), timed.
// Usage (each frame, after ProgressiveRenderer::add_frame):
//   PreviewInputs in(w, h);
//   const Accumulation& a = renderer.accumulation();
//   in.upload(&a.lv_mean[0].x, &a.hv_mean[0].x, renderer.variance_of_mean().data());
//   ... filter.run(in, range.guide(), ...); blend.run(in, &filter, ...);
#pragma once
#include <cstdint>
#include <vector>
#include "gl/resources.h"

namespace pxf {

class PreviewInputs {
 public:
  PreviewInputs(int width, int height);
  int width() const { return width_; }
  int height() const { return height_; }

  // lv_rgb, hv_rgb: 3 floats per pixel, top row first. var_of_mean: Var[L_u] per pixel, negative
  // where unknown (n < 2). samples (optional): per-pixel n; where n < 2 the variance is marked
  // unknown whatever var_of_mean says (for callers holding a variance image with 0 there).
  void upload(const float* lv_rgb, const float* hv_rgb, const float* var_of_mean,
              const uint32_t* samples = nullptr);
  // The same from images: lv, hv "R,G,B"; var one channel.
  void upload(const Image& lv, const Image& hv, const Image& var);
  // The per-pixel mean albedo of the first non-specular vertex (Accumulation::albedo_mean, 3 floats
  // per pixel), for albedo demodulation (gl/demodulation.h). Uploaded only when demodulating.
  void upload_albedo(const float* albedo_rgb);
  void upload_albedo(const Image& albedo);  // "R,G,B"

  const Texture2D& lv() const { return lv_; }  // rgb L_lv
  const Texture2D& hv() const { return hv_; }  // rgb L_u, a Var[L_u] (kVarUnknown where n < 2)
  const Texture2D& albedo() const { return albedo_; }  // rgb mean albedo (upload_albedo)
  double last_upload_ms() const { return timer_.last_ms(); }

  Image lv_image() const;   // "R,G,B"
  Image hv_image() const;   // "R,G,B"
  Image var_image() const;  // "Y": Var[L_u], 0 where unknown
  Image albedo_image() const;  // "R,G,B"

 private:
  int width_, height_;
  Texture2D lv_, hv_, albedo_;
  std::vector<float> packed_;  // staging: hv rgb + variance interleaved
  StageTimer timer_;
};

}  // namespace pxf
