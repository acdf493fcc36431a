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

void GridFilter::run(const PreviewInputs& inputs, const Texture2D& guide, const FilterParams& p, float t,
                     const Framebuffer& target) {
  resize_grid(grid_layout(width_, height_, p));
  const glm::ivec2 grid_xy(layout_.nx, layout_.ny);
  const float inv_cell_s = 1.0f / layout_.cell_s;
  const uint32_t initial_bounds[2] = {0x7f7fffffu, 0u};  // FLT_MAX, +0
  step_timer_.begin();
  bounds_buffer_.upload(initial_bounds, sizeof initial_bounds);
  bounds_buffer_.bind_storage(shared::kBufferGridBounds);

  bounds_.use();
  bounds_.bind(shared::kUnitGuide, guide);
  bounds_.require_inputs();
  const int strips = (width_ + 63) / 64 * height_;  // 64-pixel row strips (grid_bounds.comp)
  dispatch_compute_1d("grid filter bounds", (strips + 63) / 64);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);

  step_ms_[0] = step_timer_.end();
  step_timer_.begin();
  splat_.set("grid_xy", grid_xy);
  splat_.set("cell_s", layout_.cell_s);
  splat_.set("inv_cell_s", inv_cell_s);
  splat_.set("min_cell_z", grid_min_cell_z(p.sigma_c));
  splat_.use();
  splat_.bind(shared::kUnitHv, inputs.hv());
  splat_.bind(shared::kUnitGuide, guide);
  splat_.require_inputs();
  grid_[0].bind_storage(shared::kBufferGrid);
  dispatch_compute("grid filter splat", (layout_.nx + 7) / 8, (layout_.ny + 7) / 8);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);

  step_ms_[1] = step_timer_.end();
  step_timer_.begin();
  blur_.set("grid_xy", grid_xy);
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

  step_ms_[2] = step_timer_.end();
  step_timer_.begin();
  const RangeWeights range = range_weights(p);
  slice_.set("grid_xy", grid_xy);
  slice_.set("inv_cell_s", inv_cell_s);
  slice_.set("min_cell_z", grid_min_cell_z(p.sigma_c));
  slice_.set("k_c", range.k_c);
  slice_.set("k_d", range.k_d);
  slice_.set("skip_case2", p.skip_case2 ? 1 : 0);
  slice_.set("t", t);
  slice_.use();
  slice_.bind(shared::kUnitHv, inputs.hv());
  slice_.bind(shared::kUnitLv, inputs.lv());
  slice_.bind(shared::kUnitGuide, guide);
  grid_[0].bind_storage(shared::kBufferGrid);
  quad_.draw(slice_, target, width_, height_);
  step_ms_[3] = step_timer_.end();
}

}  // namespace pxf
