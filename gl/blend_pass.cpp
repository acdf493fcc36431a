#include "gl/blend_pass.h"

#include "gl/gl.h"

namespace pxf {

BlendPass::BlendPass(int width, int height)
    : width_(width), height_(height), program_(Program::from_embedded("fullscreen.vert", "blend.frag")),
      guard_rows_program_(Program::from_embedded("fullscreen.vert", "bias_guard_rows.frag")),
      guard_columns_program_(Program::from_embedded("fullscreen.vert", "bias_guard_columns.frag")),
      output_(width, height, TextureFormat::RGBA32F), case_(width, height, TextureFormat::R32F),
      guard_rows_(width, height, TextureFormat::RGBA32F), guard_rows_low_x_(width, height, TextureFormat::RGBA32F),
      guard_rows_high_x_(width, height, TextureFormat::RGBA32F), guard_(width, height, TextureFormat::RGBA32F),
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

void BlendPass::run_bias_guard(const PreviewInputs& inputs, const Texture2D& filtered, bool split) {
  ++guard_runs_;
  guard_rows_program_.use();
  guard_rows_program_.bind(shared::kUnitHv, inputs.hv());
  guard_rows_program_.bind(shared::kUnitFiltered, filtered);
  quad_.draw(guard_rows_program_, guard_rows_fbo_, width_, height_);
  guard_columns_program_.use();
  guard_columns_program_.bind(shared::kUnitGuardSums, guard_rows_);
  guard_columns_program_.bind(shared::kUnitGuardRowsLowX, guard_rows_low_x_);
  guard_columns_program_.bind(shared::kUnitGuardRowsHighX, guard_rows_high_x_);
  guard_columns_program_.bind(shared::kUnitHv, inputs.hv());
  guard_columns_program_.bind(shared::kUnitFiltered, filtered);
  guard_columns_program_.bind(shared::kUnitHalves, inputs.halves());
  guard_columns_program_.bind(shared::kUnitHalfVariances, inputs.half_variances());
  guard_columns_program_.set("split", split ? 1 : 0);
  quad_.draw(guard_columns_program_, guard_fbo_, width_, height_);
}

void BlendPass::run(const PreviewInputs& inputs, const FilterPass* filtered, const Texture2D& guide, float t,
                    const BlendParams& params, const Texture2D* surface) {
  const bool has = filtered && filtered->has_output();
  run(inputs, has ? &filtered->output() : nullptr, &guide, t, params, has ? filtered->centre_weight() : nullptr,
      surface);
}

void BlendPass::run(const PreviewInputs& inputs, const Texture2D* filtered, const Texture2D* guide, float t,
                    const BlendParams& params, const Texture2D* centre_weight, const Texture2D* surface) {
  auto other_size = [&](const Texture2D* tex) { return tex && (tex->width() != width_ || tex->height() != height_); };
  if (inputs.width() != width_ || inputs.height() != height_ || other_size(filtered) || other_size(guide) ||
      other_size(centre_weight) || other_size(surface))
    throw Error("blend pass: input size differs from the pass size");
  timer_.begin();
  const bool guard = params.bias_guard && filtered;
  const bool split = params.split && inputs.has_halves();
  if (guard) run_bias_guard(inputs, *filtered, split);
  if (!guide) surface = nullptr;
  RangeWeights range = params.range;
  if (!surface) range.k_n = range.k_r = 0.0f;  // no surface buffer: no surface terms
  last_ = LastRun{&inputs.hv(), &inputs.lv(), filtered, guide, filtered ? centre_weight : nullptr, surface,
                  split ? &inputs.halves() : nullptr, split ? &inputs.half_variances() : nullptr,
                  shared::BlendSwitches{filtered != nullptr, guide != nullptr, guard, t, params.samples}, range};
  program_.set("has_filtered", last_.switches.has_filtered ? 1 : 0);
  program_.set("has_guide", last_.switches.has_guide ? 1 : 0);
  program_.set("has_centre_weight", last_.centre_weight ? 1 : 0);
  program_.set("k_c", range.k_c);
  program_.set("k_d", range.k_d);
  program_.set("k_n", range.k_n);
  program_.set("k_r", range.k_r);
  program_.set("t", t);
  program_.set("samples", last_.switches.samples);
  program_.set("bias_guard", last_.switches.bias_guard ? 1 : 0);
  program_.set("split", split ? 1 : 0);
  const std::array<uint32_t, kBlendCaseCount> zeros{};
  counts_.upload(zeros.data(), sizeof zeros);
  counts_.bind_storage(shared::kBufferCounts);
  program_.use();
  program_.bind(shared::kUnitHv, inputs.hv());
  program_.bind(shared::kUnitLv, inputs.lv());
  // Unused units still get a texture, so every sampler is valid.
  program_.bind(shared::kUnitFiltered, filtered ? *filtered : inputs.hv());
  program_.bind(shared::kUnitGuide, guide ? *guide : inputs.hv());
  program_.bind(shared::kUnitSurface, surface ? *surface : inputs.hv());
  program_.bind(shared::kUnitCentreWeight, centre_weight ? *centre_weight : inputs.hv());
  program_.bind(shared::kUnitGuardSums, guard_);
  program_.bind(shared::kUnitHalves, inputs.halves());
  program_.bind(shared::kUnitHalfVariances, inputs.half_variances());
  quad_.draw(program_, fbo_, width_, height_);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
  timer_.end();
  check_gl_error("blend pass");
}

std::array<uint32_t, kBlendCaseCount> BlendPass::case_counts() const {
  std::array<uint32_t, kBlendCaseCount> counts{};
  counts_.download(counts.data(), sizeof counts);
  return counts;
}

namespace {

// A texture as the shared code reads a sampler (shaders/cpu_gpu.h), one read-back per texel.
struct TextureTexels {
  const Texture2D* texture;
};
// No texture: 0, an unknown surface (the surface terms are off then anyway).
glm::vec4 texelFetch(const TextureTexels& t, glm::ivec2 p, int) {
  return t.texture ? t.texture->texel(p.x, p.y) : glm::vec4(0.0f);
}
glm::ivec2 textureSize(const TextureTexels& t, int) { return {t.texture->width(), t.texture->height()}; }

}  // namespace

// blend.frag's reads, on the same textures.
BlendInspection BlendPass::inspect(int x, int y) const {
  if (!last_.hv) throw Error("blend pass: inspected before its first run");
  const glm::ivec2 p(x, y);
  BlendInspection i;
  i.switches = last_.switches;
  i.texels = {last_.hv->texel(x, y), last_.lv->texel(x, y), (last_.filtered ? last_.filtered : last_.hv)->texel(x, y),
              last_.guide ? last_.guide->texel(x, y).a : 0.0f};
  shared::PooledNeighbours pooled{0.0, 0.0, 0.0};
  if (last_.guide && shared::blend_case_before_variances(i.texels, i.switches) == shared::kCaseByVariances)
    pooled = shared::pooled_neighbours(TextureTexels{last_.hv}, TextureTexels{last_.guide},
                                       TextureTexels{last_.surface}, p, last_.range.k_c, last_.range.k_d,
                                       last_.range.k_n, last_.range.k_r);
  const glm::vec4 guard = last_.switches.bias_guard ? guard_.texel(x, y) : glm::vec4(0.0f);
  const float centre_weight = last_.centre_weight ? last_.centre_weight->texel(x, y).r : 0.0f;
  auto inputs = [&](const shared::BlendTexels& px, glm::vec2 g) {
    return shared::blend_variance_inputs(px, i.switches, pooled, centre_weight, g);
  };
  i.split = last_.halves != nullptr;
  if (!i.split) {
    i.variance_inputs = inputs(i.texels, glm::vec2(guard.x, guard.y));
    i.decision = shared::blend_pixel(i.texels, i.switches, i.variance_inputs);
    return i;
  }
  i.halves = last_.halves->texel(x, y);
  i.half_variances = glm::vec2(last_.half_variances->texel(x, y));
  i.variance_inputs = inputs(shared::decision_texels(i.texels, i.half_variances, 0), glm::vec2(guard.x, guard.y));
  i.odd_variance_inputs = inputs(shared::decision_texels(i.texels, i.half_variances, 1), glm::vec2(guard.z, guard.w));
  i.decision = shared::blend_pixel_split(i.texels, i.halves, i.half_variances, i.switches, i.variance_inputs,
                                         i.odd_variance_inputs);
  return i;
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
