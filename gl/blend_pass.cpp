#include "gl/blend_pass.h"

#include "gl/gl.h"

namespace pxf {

BlendPass::BlendPass(int width, int height)
    : width_(width), height_(height), program_(Program::from_embedded("fullscreen.vert", "blend.frag")),
      guard_rows_program_(Program::from_embedded("fullscreen.vert", "bias_guard_rows.frag")),
      guard_columns_program_(Program::from_embedded("fullscreen.vert", "bias_guard_columns.frag")),
      output_(width, height, TextureFormat::RGBA32F), case_(width, height, TextureFormat::R32F),
      guard_rows_(width, height, TextureFormat::RGBA32F), guard_rows_low_x_(width, height, TextureFormat::RGBA32F),
      guard_rows_high_x_(width, height, TextureFormat::RGBA32F), guard_(width, height, TextureFormat::RG32F),
      counts_(sizeof(uint32_t) * kBlendCaseCount) {
  fbo_.attach(0, output_);
  fbo_.attach(1, case_);
  fbo_.check("blend pass");
  guard_rows_fbo_.attach(0, guard_rows_);
  guard_rows_fbo_.attach(1, guard_rows_low_x_);
  guard_rows_fbo_.attach(2, guard_rows_high_x_);
  guard_rows_fbo_.check("blend pass, bias guard rows");
  guard_fbo_.attach(0, guard_);
  guard_fbo_.check("blend pass, bias guard");
}

void BlendPass::run_bias_guard(const PreviewInputs& inputs, const Texture2D& filtered) {
  ++guard_runs_;
  inputs.hv().bind(shared::kUnitHv);
  filtered.bind(shared::kUnitFiltered);
  guard_rows_program_.use();
  quad_.draw(guard_rows_fbo_, width_, height_);
  guard_rows_.bind(shared::kUnitGuardSums);
  guard_rows_low_x_.bind(shared::kUnitGuardRowsLowX);
  guard_rows_high_x_.bind(shared::kUnitGuardRowsHighX);
  guard_columns_program_.use();
  quad_.draw(guard_fbo_, width_, height_);
}

void BlendPass::run(const PreviewInputs& inputs, const FilterPass* filtered, const Texture2D& guide, float t,
                    const BlendParams& params) {
  const bool has = filtered && filtered->has_output();
  run(inputs, has ? &filtered->output() : nullptr, &guide, t, params, has ? filtered->centre_weight() : nullptr);
}

void BlendPass::run(const PreviewInputs& inputs, const Texture2D* filtered, const Texture2D* guide, float t,
                    const BlendParams& params, const Texture2D* centre_weight) {
  auto other_size = [&](const Texture2D* tex) { return tex && (tex->width() != width_ || tex->height() != height_); };
  if (inputs.width() != width_ || inputs.height() != height_ || other_size(filtered) || other_size(guide) ||
      other_size(centre_weight))
    throw Error("blend pass: input size differs from the pass size");
  timer_.begin();
  const bool guard = params.bias_guard && filtered;
  if (guard) run_bias_guard(inputs, *filtered);
  program_.set("has_filtered", filtered ? 1 : 0);
  program_.set("has_guide", guide ? 1 : 0);
  program_.set("has_centre_weight", filtered && centre_weight ? 1 : 0);
  program_.set("k_c", params.range.k_c);
  program_.set("k_d", params.range.k_d);
  program_.set("t", t);
  program_.set("bias_guard", guard ? 1 : 0);
  const std::array<uint32_t, kBlendCaseCount> zeros{};
  counts_.upload(zeros.data(), sizeof zeros);
  counts_.bind_storage(shared::kBufferCounts);
  inputs.hv().bind(shared::kUnitHv);
  inputs.lv().bind(shared::kUnitLv);
  // Unused units still get a texture, so every sampler is valid.
  (filtered ? *filtered : inputs.hv()).bind(shared::kUnitFiltered);
  (guide ? *guide : inputs.hv()).bind(shared::kUnitGuide);
  (centre_weight ? *centre_weight : inputs.hv()).bind(shared::kUnitCentreWeight);
  guard_.bind(shared::kUnitGuardSums);
  program_.use();
  quad_.draw(fbo_, width_, height_);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
  timer_.end();
  check_gl_error("blend pass");
}

std::array<uint32_t, kBlendCaseCount> BlendPass::case_counts() const {
  std::array<uint32_t, kBlendCaseCount> counts{};
  counts_.download(counts.data(), sizeof counts);
  return counts;
}

Image BlendPass::final_image() const { return output_.download({"R", "G", "B"}); }
Image BlendPass::s_image() const {
  Image rgba = output_.download({"R", "G", "B", "A"});
  Image out = Image::gray(width_, height_);
  for (size_t i = 0; i < out.pixel_count(); ++i) out.pixels[i] = rgba.pixels[4 * i + 3];
  return out;
}
Image BlendPass::case_image() const { return case_.download({"Y"}); }

}  // namespace pxf
