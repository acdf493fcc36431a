// The per-frame inputs of the filter and blend passes, as persistent GL textures: one upload per
// buffer per frame (glTextureSubImage2D), timed.
// Usage (each frame, after ProgressiveRenderer::add_frame):
//   PreviewInputs in(w, h);
//   const Accumulation& a = renderer.accumulation();
//   a.hv_and_variance_of_mean(hv_rgba.data());   // the packed HV texture, filled by the renderer
//   in.upload_packed(&a.lv_mean[0].x, hv_rgba.data());
//   ... filter.run(in, range.guide(), ...); blend.run(in, &filter, ...);
#pragma once
#include <cstdint>
#include <memory>
#include <vector>
#include "gl/resources.h"

namespace pxf {

class PreviewInputs {
 public:
  PreviewInputs(int width, int height);
  int width() const { return width_; }
  int height() const { return height_; }

  // lv_rgb: 3 floats per pixel, top row first. hv_rgba: 4 floats per pixel, rgb L_u, a Var[L_u]
  // (kVarUnknown where n < 2), the HV texture's layout: uploaded as it is, without a copy. The LV
  // texture's alpha, the pixels' threshold factor (shared::pixel_threshold), is 1: every pixel holds
  // the frame count's samples.
  void upload_packed(const float* lv_rgb, const float* hv_rgba);
  // The same with each pixel's own threshold factor: lv_rgba 4 floats per pixel, rgb L_lv, a the
  // factor t_{n_p} / t_n of a pixel that holds n_p samples where the run's threshold is t_n
  // (adaptive sampling).
  void upload_packed_with_threshold(const float* lv_rgba, const float* hv_rgba);
  // The same from separate buffers: hv_rgb 3 floats per pixel, var_of_mean one (kVarUnknown where
  // n < 2), interleaved into a staging buffer first.
  void upload(const float* lv_rgb, const float* hv_rgb, const float* var_of_mean);
  // The same from images: lv "R,G,B" (or "R,G,B,A", A the threshold factor), hv "R,G,B"; var one channel.
  void upload(const Image& lv, const Image& hv, const Image& var);
  // The per-pixel mean albedo of the first non-delta vertex (Accumulation::albedo_mean, 3 floats
  // per pixel), for albedo demodulation (gl/demodulation.h). Uploaded only when demodulating.
  void upload_albedo(const float* albedo_rgb);
  void upload_albedo(const Image& albedo);  // "R,G,B"
  // The halves of each pixel's samples for the blend's split decision (Accumulation::hv_halves):
  // halves 4 floats per pixel (rgb the even half's mean, a its share n_even / n), variances 2 (the
  // whole mean's variance from each half alone, even then odd; kVarUnknown below 2 samples). Valid
  // until the next upload of the HV texture (has_halves).
  void upload_halves(const float* halves_rgba, const float* variances_rg);
  void upload_halves(const Image& halves, const Image& variances);  // "R,G,B,A" and two channels
  bool has_halves() const { return has_halves_; }

  const Texture2D& lv() const { return lv_; }  // rgb L_lv, a the pixel's threshold factor
  const Texture2D& hv() const { return hv_; }  // rgb L_u, a Var[L_u] (kVarUnknown where n < 2)
  const Texture2D& albedo() const { return albedo_; }  // rgb mean albedo (upload_albedo)
  // rgb L_even, a n_even / n, and rg (V_even, V_odd) (upload_halves). Allocated by the first
  // upload_halves: before it the HV texture stands in, so that every sampler unit has a texture (no
  // pass reads it then: has_halves is false).
  const Texture2D& halves() const { return halves_ ? *halves_ : hv_; }
  const Texture2D& half_variances() const { return half_variances_ ? *half_variances_ : hv_; }
  double last_upload_ms() const { return timer_.last_ms(); }

  Image lv_image() const;   // "R,G,B"
  Image hv_image() const;   // "R,G,B"
  Image var_image() const;  // "Y": Var[L_u], 0 where unknown
  Image albedo_image() const;  // "R,G,B"

 private:
  int width_, height_;
  Texture2D lv_, hv_, albedo_;
  std::unique_ptr<Texture2D> halves_, half_variances_;  // the split decision's, when it is on
  bool has_halves_ = false;
  std::vector<float> packed_;  // staging of upload(): hv rgb + variance interleaved
  StageTimer timer_;
};

}  // namespace pxf
