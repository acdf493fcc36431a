// Albedo demodulation around the filter, for every filter variant: the filter smooths HV divided by
// the directional albedo of the first non-delta vertex (PathSample::albedo; its pixel mean is
// coverage x albedo), so it sees illumination, free of texture detail, and its output is multiplied
// back by each pixel's own albedo before the blend, so textures and thin strands stay sharp.
// The formulas are shared with the CPU reference (shaders/pass_formulas.h): demodulated_texel
// (per channel, with modulation_factor; a pixel below kAlbedoEpsilon takes its neighbours' light)
// and remodulated_texel. On an unfiltered, demodulated pixel the two steps give back L_u and
// Var[L_u]; the blend sees L_f and Var[L_f] in radiance units, so its perceived-variance logic is
// unchanged. The filter's case-2 skip is decided on the original buffers (shaders/demodulate.frag).
// CPU reference: cpu_demodulate / cpu_remodulate.
// Usage:
//   inputs.upload_albedo(&acc.albedo_mean[0].x);
//   demod.demodulate(inputs, guide, filter_params, t);
//   filter.run(demod.filter_inputs(), guide, filter_params, t);
//   demod.remodulate(filter.output(), inputs);
//   blend.run(inputs, &demod.output(), &guide, t, blend_params, filter.centre_weight());  // w unchanged
#pragma once
#include "gl/inputs.h"
#include "gl/pass_params.h"
#include "gl/resources.h"

namespace pxf {

class Demodulation {
 public:
  Demodulation(int width, int height);
  // inputs: L_u, Var[L_u], L_lv and the albedo (PreviewInputs::upload_albedo); guide: the range
  // buffer; params: the filter's (range weights, skip_case2); t: the blend threshold, for the skip decision.
  // surface: the range pass's surface buffer for the skip's surface terms; nullptr leaves them out.
  void demodulate(const PreviewInputs& inputs, const Texture2D& guide, const FilterParams& params, float t,
                  const Texture2D* surface = nullptr);
  const PreviewInputs& filter_inputs() const { return filter_inputs_; }  // the filter's input
  // filtered: the filter's output on filter_inputs(); albedo from `inputs`.
  void remodulate(const Texture2D& filtered, const PreviewInputs& inputs);
  const Texture2D& output() const { return output_; }  // rgb L_f, a Var[L_f] or a sentinel
  double last_ms() const { return demod_timer_.last_ms() + remod_timer_.last_ms(); }

  Image filtered_image() const;      // "R,G,B" L_f
  Image variance_image() const;      // "Y" Var[L_f], 0 where unknown or skipped

 private:
  int width_, height_;
  Program demod_program_, remod_program_;
  PreviewInputs filter_inputs_;
  Texture2D output_;
  Framebuffer demod_fbo_, remod_fbo_;
  FullscreenPass quad_;
  StageTimer demod_timer_, remod_timer_;
};

}  // namespace pxf
