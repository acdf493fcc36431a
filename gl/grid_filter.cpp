#include "gl/grid_filter.h"

#include "gl/dispatch.h"
#include "gl/gl.h"

namespace pxf {

GridFilter::GridFilter(int width, int height)
    : width_(width), height_(height), bounds_(Program::from_embedded_compute("grid_bounds.comp")),
      splat_(Program::from_embedded_compute("grid_splat.comp")),
      blur_(Program::from_embedded_compute("grid_blur.comp")),
      slice_(Program::from_embedded("fullscreen.vert", "grid_slice.frag")), bounds_buffer_(2 * sizeof(uint32_t)) {}

void GridFilter::resize_grid(const GridLayout& layout) {
  const size_t bytes = layout.cells() * 2 * 4 * sizeof(float);
  if (grid_[0].size() < bytes)
    for (Buffer& b : grid_) b = Buffer(bytes);
  layout_ = layout;
}

void GridFilter::begin(const PreviewInputs& inputs, const Texture2D& guide, const FilterParams& p, float t,
                       const Framebuffer& target, const Texture2D* surface) {
  resize_grid(grid_layout(width_, height_, p));
  inputs_ = &inputs, guide_ = &guide, surface_ = surface, target_ = &target;
  params_ = p, t_ = t;
  next_step_ = 0;
}

bool GridFilter::step() {
  if (next_step_ >= kSteps) throw Error("grid filter: step() without a run in progress (begin() first)");
  step_timer_.begin();
  switch (next_step_) {
    case 0: run_bounds(); break;
    case 1: run_splat(); break;
    case 2: run_blur(); break;
    default: run_slice(); break;
  }
  step_ms_[next_step_] = step_timer_.end();
  return ++next_step_ == kSteps;
}

void GridFilter::run_bounds() {
  const uint32_t initial_bounds[2] = {0x7f7fffffu, 0u};  // FLT_MAX, +0
  bounds_buffer_.upload(initial_bounds, sizeof initial_bounds);
  bounds_buffer_.bind_storage(shared::kBufferGridBounds);
  bounds_.use();
  bounds_.bind(shared::kUnitGuide, *guide_);
  bounds_.require_inputs();
  const int strips = (width_ + 63) / 64 * height_;  // 64-pixel row strips (grid_bounds.comp)
  dispatch_compute_1d("grid filter bounds", (strips + 63) / 64);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
}

void GridFilter::run_splat() {
  splat_.set("grid_xy", glm::ivec2(layout_.nx, layout_.ny));
  splat_.set("cell_s", layout_.cell_s);
  splat_.set("inv_cell_s", 1.0f / layout_.cell_s);
  splat_.set("min_cell_z", grid_min_cell_z(params_.sigma_c));
  splat_.use();
  splat_.bind(shared::kUnitHv, inputs_->hv());
  splat_.bind(shared::kUnitGuide, *guide_);
  splat_.require_inputs();
  bounds_buffer_.bind_storage(shared::kBufferGridBounds);
  grid_[0].bind_storage(shared::kBufferGrid);
  dispatch_compute("grid filter splat", (layout_.nx + 7) / 8, (layout_.ny + 7) / 8);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
}

void GridFilter::run_blur() {
  blur_.set("grid_xy", glm::ivec2(layout_.nx, layout_.ny));
  blur_.set("grid_z_cells", layout_.nz);
  blur_.use();
  blur_.require_inputs();
  const uint64_t groups = (layout_.cells() + 63) / 64;
  for (int axis = 0; axis < 2; ++axis) {  // z was blurred in the splat
    blur_.set("axis", axis);
    grid_[axis % 2].bind_storage(shared::kBufferGrid);
    grid_[1 - axis % 2].bind_storage(shared::kBufferGridTarget);
    dispatch_compute_1d("grid filter blur", groups);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
  }
}

void GridFilter::run_slice() {
  const RangeWeights range = range_weights(params_);
  slice_.set("grid_xy", glm::ivec2(layout_.nx, layout_.ny));
  slice_.set("inv_cell_s", 1.0f / layout_.cell_s);
  slice_.set("min_cell_z", grid_min_cell_z(params_.sigma_c));
  slice_.set("k_c", range.k_c);
  slice_.set("k_d", range.k_d);
  slice_.set("k_n", surface_ ? range.k_n : 0.0f);
  slice_.set("k_r", surface_ ? range.k_r : 0.0f);
  slice_.set("skip_case2", filter_skip_mode(params_, inputs_->has_halves()));
  slice_.set("t", t_);
  slice_.use();
  slice_.bind(shared::kUnitHv, inputs_->hv());
  slice_.bind(shared::kUnitLv, inputs_->lv());
  slice_.bind(shared::kUnitGuide, *guide_);
  slice_.bind(shared::kUnitSurface, surface_ ? *surface_ : *guide_);
  slice_.bind(shared::kUnitHalfVariances, inputs_->half_variances());
  bounds_buffer_.bind_storage(shared::kBufferGridBounds);
  grid_[0].bind_storage(shared::kBufferGrid);
  quad_.draw(slice_, *target_, width_, height_);
}

}  // namespace pxf
