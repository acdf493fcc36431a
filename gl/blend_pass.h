// Blend pass (docs/method.md section 3): per pixel s from u = Var[L_u]/L_b^2 and f = Var[L_f]/L_b^2 and threshold t,
// composite L = L_lv + s L_u + (1 - s) L_f. Runs every displayed frame with the newest L_f.
// Usage:
//   BlendPass blend(w, h);
//   blend.run(inputs, &filter, range.guide(), t, {range_weights(filter_params)});
//   tonemap.run(blend.output(), tonemap_params);
//   auto counts = blend.case_counts();  // e.g. counts[kCaseUnfiltered] == w*h: stop filtering
//   blend.final_image(), blend.s_image(), blend.case_image(), blend.last_ms()
//   blend.inspect(x, y).decision  // one pixel decided again as the pass did (the explorer's inspector)
#pragma once
#include <array>
#include "gl/filter_pass.h"
#include "gl/inputs.h"
#include "gl/pass_params.h"
#include "gl/resources.h"

namespace pxf {

// One pixel as the last blend run decided it (BlendPass::inspect, the explorer's inspector): the
// texels the pass read there, the run's switches, what it read where it compared variances, and
// shared::blend_pixel on them, the shader's decision compiled as C++.
struct BlendInspection {
  shared::BlendTexels texels;
  shared::BlendSwitches switches;
  shared::BlendVarianceInputs variance_inputs;  // under the split decision, the even half's
  shared::BlendPixel decision;
  bool split = false;  // decided by halves (shared::blend_pixel_split)
  glm::vec4 halves{0.0f};
  glm::vec2 half_variances{0.0f};
  shared::BlendVarianceInputs odd_variance_inputs{};
};

class BlendPass {
 public:
  BlendPass(int width, int height);
  // filtered == nullptr (or without output): no L_f yet, s = 1 everywhere (kCaseNoFiltered).
  // guide: the range buffer (rgb color, a distance), for the 3x3 variance pooling of u. t: the
  // perceived-variance threshold (the filter's skip used the same).
  // surface: the range pass's surface buffer (RangePass::surface()) for the pooling's surface
  // terms; nullptr leaves them out.
  void run(const PreviewInputs& inputs, const FilterPass* filtered, const Texture2D& guide, float t,
           const BlendParams& params, const Texture2D* surface = nullptr);
  // Same with a raw L_f texture (rgb L_f, a Var[L_f]); guide == nullptr: u from each pixel's own
  // variance (no pooling). Used by tests and custom filters.
  // centre_weight (r: the filter's normalized centre weight, FilterPass::centre_weight()) adds the
  // covariance of L_u and L_f to the blend's variance; nullptr leaves it out.
  void run(const PreviewInputs& inputs, const Texture2D* filtered, const Texture2D* guide, float t,
           const BlendParams& params, const Texture2D* centre_weight = nullptr, const Texture2D* surface = nullptr);

  const Texture2D& output() const { return output_; }       // rgb L, a s
  const Texture2D& case_texture() const { return case_; }   // r: case code (kCase* in shaders/pass_formulas.h)
  // Pixels per case of the last run (a 24-byte read-back).
  std::array<uint32_t, kBlendCaseCount> case_counts() const;
  double last_ms() const { return timer_.last_ms(); }
  int guard_runs() const { return guard_runs_; }  // runs that ran the bias guard's passes

  Image final_image() const;  // "R,G,B"
  Image s_image() const;      // "Y"
  Image case_image() const;   // "Y"

  // Pixel (x, y) of the last run, decided again from the textures that run read, read back texel
  // by texel (one pixel at a time): they must still hold what it read, as the preview's do until
  // its next upload. The C++ sums in double where the shader sums in float, so s agrees with the
  // pass to rounding.
  BlendInspection inspect(int x, int y) const;
  bool has_run() const { return last_.hv != nullptr; }

 private:
  // The bias guard's finding (bias_guard_estimate in shaders/pass_formulas.h) into guard_: a row
  // pass of 5 reads writes the row sums of three x ranges, a column pass of 5 reads of each adds
  // them into the 5x5 window and its four halves and judges them.
  void run_bias_guard(const PreviewInputs& inputs, const Texture2D& filtered, bool split);

  // What the last run read and its switches (the shader's uniforms), for inspect().
  struct LastRun {
    const Texture2D* hv = nullptr;
    const Texture2D* lv = nullptr;
    const Texture2D* filtered = nullptr;
    const Texture2D* guide = nullptr;
    const Texture2D* centre_weight = nullptr;
    const Texture2D* surface = nullptr;
    const Texture2D* halves = nullptr;  // the split decision's; nullptr: one decision
    const Texture2D* half_variances = nullptr;
    shared::BlendSwitches switches{};
    RangeWeights range;
  };

  int width_, height_;
  Program program_;
  Program guard_rows_program_, guard_columns_program_;
  Texture2D output_, case_;
  Texture2D guard_rows_, guard_rows_low_x_, guard_rows_high_x_, guard_;
  Framebuffer fbo_, guard_rows_fbo_, guard_fbo_;
  Buffer counts_;
  FullscreenPass quad_;
  StageTimer timer_;
  int guard_runs_ = 0;
  LastRun last_;
};

}  // namespace pxf
