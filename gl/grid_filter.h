// Bilateral-grid variant of the filter pass (FilterKind::Grid; Chen, Paris and Durand 2007), run
// by FilterPass. Four GL steps, all a real GPU runs unchanged: the guide luminance's bounds
// (shaders/grid_bounds.comp), the splat of L_u and its variance into a coarse 3D grid
// (grid_splat.comp, which also blurs along z), the blur along x and y (grid_blur.comp) and the
// per-pixel trilinear slice with the case-2 skip (grid_slice.frag), which writes FilterPass's
// output. Layout and the variance it computes: gl/grid_layout.h, gl/grid_reference.cpp.
#pragma once
#include <array>
#include "gl/grid_layout.h"
#include "gl/inputs.h"
#include "gl/resources.h"

namespace pxf {

class GridFilter {
 public:
  GridFilter(int width, int height);
  // A run one GL step at a time (FilterPass::step; the explorer's frame budget spreads them over
  // display frames). begin() keeps the arguments, which must outlive the run: inputs: L_u (splat,
  // slice) and L_lv (the slice's skip); guide: the range buffer; t: the blend threshold, for the
  // case-2 skip. Each step() runs the next step and binds all it reads (other passes may run
  // between two steps) but the filtered-pixel counter, which the caller binds at kBufferCounts;
  // true after the slice, which draws rgb L_f, a Var[L_f] into `target`. A begin() abandons a run
  // in progress.
  // surface (RangePass::surface(), may be nullptr): for the skip's range weights only; the grid's
  // kernel has one range axis, the guide's luminance, and no surface terms.
  void begin(const PreviewInputs& inputs, const Texture2D& guide, const FilterParams& params, float t,
             const Framebuffer& target, const Texture2D* surface = nullptr);
  bool step();
  static constexpr int kSteps = 4;
  // ms of the last run's steps (bounds, splat, blur, slice), measured as gl_timing() says.
  static constexpr const char* kStepNames[kSteps] = {"bounds", "splat", "blur", "slice"};
  const std::array<double, kSteps>& last_step_ms() const { return step_ms_; }

 private:
  void resize_grid(const GridLayout& layout);
  void run_bounds();
  void run_splat();
  void run_blur();
  void run_slice();

  int width_, height_;
  Program bounds_, splat_, blur_, slice_;
  Buffer bounds_buffer_;
  Buffer grid_[2];  // ping-pong: splat (and blur z) into 0, blur x -> 1, y -> 0, slice from 0
  GridLayout layout_;
  FullscreenPass quad_;
  StageTimer step_timer_;
  std::array<double, kSteps> step_ms_{};
  // The run in progress (begin()).
  const PreviewInputs* inputs_ = nullptr;
  const Texture2D* guide_ = nullptr;
  const Texture2D* surface_ = nullptr;
  const Framebuffer* target_ = nullptr;
  FilterParams params_;
  float t_ = 0;
  int next_step_ = kSteps;
};

}  // namespace pxf
