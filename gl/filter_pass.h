// Cross bilateral filter pass (docs/method.md section 2; FilterKind picks the variant: shaders/bilateral.frag,
// shaders/atrous.frag for the à-trous one, shaders/subsampled.frag for the subsampled one): L_f and Var[L_f] from the HV buffer, guided by the
// range buffer (color + distance). Runs on a schedule; the output texture persists between runs.
// Usage:
//   FilterPass filter(w, h);
//   filter.run(inputs, range.guide(), params, t);    // t: the blend's threshold (for skipping)
//   blend.run(inputs, &filter, range.guide(), t, blend_params);  // uses filter.output()
//   filter.filtered_image(), filter.variance_image(), filter.last_ms()
// Pixels in case 2 (u <= t with the unfiltered background) are skipped: L_f = L_u there and
// Var[L_f] = kVarSkipped, the blend then uses s = 1 (see FilterParams::skip_case2).
#pragma once
#include <utility>
#include <memory>
#include "gl/grid_filter.h"
#include "gl/inputs.h"
#include "gl/pass_params.h"
#include "gl/resources.h"

namespace pxf {

class FilterPass {
 public:
  FilterPass(int width, int height);
  // guide: rgb range color, a distance (RangePass::guide()); t: the blend threshold, for the case-2
  // skip. params.kind must not be FilterKind::None (throws pxf::Error). surface: xyz shading normal,
  // w roughness (RangePass::surface()), for the range weight's surface terms (sigma_n, sigma_r);
  // nullptr leaves them out.
  void run(const PreviewInputs& inputs, const Texture2D& guide, const FilterParams& params, float t,
           const Texture2D* surface = nullptr);
  // The same run in steps, for a frame budget: the grid variant's four GL steps, the others' whole
  // run as one. begin() checks the arguments (which must outlive the run) and clears the
  // filtered-pixel count, running no pass; each step() runs the next step, true after the last,
  // when output() holds the new L_f. A begin() abandons a run in progress; until the last step
  // output() keeps the previous run's result.
  void begin(const PreviewInputs& inputs, const Texture2D& guide, const FilterParams& params, float t,
             const Texture2D* surface = nullptr);
  bool step();
  bool in_progress() const { return staged_.inputs != nullptr; }
  // Compiles the variant's program (creates its grid), which a run otherwise does on first use: a
  // caller that times runs to predict the next one (the schedule, --time's reserve) prepares
  // first, so that the first run's cost is the run's and not the set-up's.
  void prepare(FilterKind kind);

  bool has_output() const { return runs_ > 0; }
  int runs() const { return runs_; }
  const Texture2D& output() const { return output_; }  // rgb L_f, a Var[L_f] or a sentinel
  // r: the normalized weight of each pixel's own L_u in its L_f, for the blend's covariance term.
  // Written by the full-kernel bilateral variants (bilateral, bilateral-depth) only; nullptr after
  // the others (the blend then leaves Cov[L_u, L_f] out).
  const Texture2D* centre_weight() const { return has_output() && centre_weight_valid_ ? &centre_weight_ : nullptr; }
  Image centre_weight_image() const;  // "Y"
  // Pixels actually filtered (not skipped) by the last run; 0 = every pixel was in case 2.
  uint32_t filtered_pixels() const;
  double last_ms() const { return last_ms_; }  // the last whole run's, its steps added
  // The grid variant's step times of its last run (GridFilter::last_step_ms); nullptr before one.
  const GridFilter* grid() const { return grid_.get(); }

  Image filtered_image() const;  // "R,G,B" L_f
  Image variance_image() const;  // "Y" Var[L_f], 0 where unknown or skipped
  Image raw_variance_image() const;  // "Y" with the sentinels kept

 private:
  void run_bilateral(const PreviewInputs& inputs, const Texture2D& guide, const FilterParams& params, float t);
  void run_atrous(const PreviewInputs& inputs, const Texture2D& guide, const FilterParams& params, float t);
  void run_subsampled(const PreviewInputs& inputs, const Texture2D& guide, const FilterParams& params, float t);
  void run_whole_variant(const PreviewInputs& inputs, const Texture2D& guide, const FilterParams& params, float t);
  const Framebuffer& scratch_target(int index);  // allocates scratch_[index] on first use

  int width_, height_;
  Program program_;
  Program atrous_program_;  // compiled on first use
  Program subsampled_program_;  // compiled on first use
  Buffer subsampled_taps_;      // subsampled_tap_table() of the last run's sigma_s and tap count
  std::pair<float, int> subsampled_key_{-1.0f, 0};
  Texture2D output_;
  Texture2D centre_weight_;  // attachment 1 of fbo_
  bool centre_weight_valid_ = false;
  Framebuffer fbo_;
  Buffer counter_;
  // Intermediate results: the separable's horizontal pass (scratch_[0]); the à-trous passes
  // before the last (ping-pong between the two).
  Texture2D scratch_[2];
  Framebuffer scratch_fbo_[2];
  FullscreenPass quad_;
  std::unique_ptr<GridFilter> grid_;  // created on first use
  StageTimer timer_;
  int runs_ = 0;
  double last_ms_ = 0;
  // The run begin() started.
  struct Staged {
    const PreviewInputs* inputs = nullptr;
    const Texture2D* guide = nullptr;
    const Texture2D* surface = nullptr;
    FilterParams params;
    float t = 0;
    double ms = 0;  // its steps so far
  } staged_;
};

}  // namespace pxf
