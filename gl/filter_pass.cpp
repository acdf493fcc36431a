#include "gl/filter_pass.h"

#include <algorithm>
#include <cmath>
#include "gl/gl.h"

namespace pxf {

FilterPass::FilterPass(int width, int height)
    : width_(width), height_(height), program_(Program::from_embedded("fullscreen.vert", "bilateral.frag")),
      output_(width, height, TextureFormat::RGBA32F), centre_weight_(width, height, TextureFormat::R32F),
      counter_(sizeof(uint32_t)) {
  fbo_.attach(0, output_);
  fbo_.attach(1, centre_weight_);
  fbo_.check("filter pass");
}

void FilterPass::run(const PreviewInputs& inputs, const Texture2D& guide, const FilterParams& p, float t,
                     const Texture2D* surface) {
  begin(inputs, guide, p, t, surface);
  while (!step()) {
  }
}

void FilterPass::begin(const PreviewInputs& inputs, const Texture2D& guide, const FilterParams& p, float t,
                       const Texture2D* surface) {
  if (p.kind == FilterKind::None) throw Error("filter pass: filter kind none (the caller skips the filter)");
  if (inputs.width() != width_ || inputs.height() != height_ || guide.width() != width_ || guide.height() != height_ ||
      (surface && (surface->width() != width_ || surface->height() != height_)))
    throw Error("filter pass: input size differs from the pass size");
  staged_ = Staged{&inputs, &guide, surface, p, t};
  const uint32_t zero = 0;
  counter_.upload(&zero, sizeof zero);
  if (p.kind == FilterKind::Grid) {
    if (!grid_) grid_ = std::make_unique<GridFilter>(width_, height_);
    grid_->begin(inputs, guide, p, t, fbo_, surface);
  }
}

bool FilterPass::step() {
  if (!in_progress()) throw Error("filter pass: step() without a run in progress (begin() first)");
  timer_.begin();
  counter_.bind_storage(shared::kBufferCounts);  // another pass may have bound its own between steps
  const bool grid = staged_.params.kind == FilterKind::Grid;
  const bool done = grid ? grid_->step() : (run_whole_variant(*staged_.inputs, *staged_.guide, staged_.params, staged_.t), true);
  if (done) glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
  staged_.ms += timer_.end();
  if (!done) return false;
  centre_weight_valid_ = staged_.params.kind == FilterKind::Bilateral ||
                         staged_.params.kind == FilterKind::BilateralDepth || grid;
  last_ms_ = staged_.ms;
  staged_ = Staged{};
  ++runs_;
  check_gl_error("filter pass");
  return true;
}

void FilterPass::run_whole_variant(const PreviewInputs& inputs, const Texture2D& guide, const FilterParams& p, float t) {
  if (p.kind == FilterKind::Atrous)
    run_atrous(inputs, guide, p, t);
  else if (p.kind == FilterKind::Subsampled)
    run_subsampled(inputs, guide, p, t);
  else
    run_bilateral(inputs, guide, p, t);
}

namespace {
// The uniforms every variant's shader shares: range weights and the case-2 skip with threshold t.
// Without a surface buffer the surface terms are off.
void set_range_and_skip(Program& program, const FilterParams& p, float t, const Texture2D* surface,
                        const PreviewInputs& inputs) {
  const RangeWeights range = range_weights(p);
  program.set("k_c", range.k_c);
  program.set("k_d", range.k_d);
  program.set("k_n", surface ? range.k_n : 0.0f);
  program.set("k_r", surface ? range.k_r : 0.0f);
  program.set("skip_case2", filter_skip_mode(p, inputs.has_halves()));
  program.set("t", t);
}
// Makes `program` current with the inputs every variant's shader reads: L_u, L_lv (the skip), the
// guide and the surface buffer (the guide stands in where there is none: its terms are off).
void use_with_inputs(const Program& program, const PreviewInputs& inputs, const Texture2D& guide,
                     const Texture2D* surface) {
  program.use();
  program.bind(shared::kUnitHv, inputs.hv());
  program.bind(shared::kUnitLv, inputs.lv());
  program.bind(shared::kUnitGuide, guide);
  program.bind(shared::kUnitSurface, surface ? *surface : guide);
  program.bind(shared::kUnitHalfVariances, inputs.half_variances());
}
}  // namespace

void FilterPass::run_bilateral(const PreviewInputs& inputs, const Texture2D& guide, const FilterParams& p, float t) {
  const int radius = std::min(kMaxFilterRadius, static_cast<int>(std::ceil(3.0f * std::max(p.sigma_s, 0.0f))));
  program_.set("radius", radius);
  program_.set("k_s", inv_two_sigma2(p.sigma_s));
  set_range_and_skip(program_, p, t, staged_.surface, inputs);
  use_with_inputs(program_, inputs, guide, staged_.surface);
  if (p.kind == FilterKind::Separable) {
    program_.set("extent", glm::ivec2(1, 0));
    program_.set("final_pass", 0);
    program_.bind(shared::kUnitSignal, inputs.hv());
    quad_.draw(program_, scratch_target(0), width_, height_);
    program_.set("extent", glm::ivec2(0, 1));
    program_.bind(shared::kUnitSignal, scratch_[0]);
  } else {
    program_.set("extent", glm::ivec2(1, 1));
    program_.bind(shared::kUnitSignal, inputs.hv());
  }
  program_.set("final_pass", 1);
  quad_.draw(program_, fbo_, width_, height_);
}

// atrous_iterations(sigma_s) passes at hole spacing 1, 2, 4, ...: each reads the previous pass's
// output (the first reads the HV buffer), the intermediate ones ping-pong between the scratch
// textures, the last writes output_ (and alone skips case-2 pixels and counts).
void FilterPass::run_atrous(const PreviewInputs& inputs, const Texture2D& guide, const FilterParams& p, float t) {
  if (!atrous_program_.id()) atrous_program_ = Program::from_embedded("fullscreen.vert", "atrous.frag");
  set_range_and_skip(atrous_program_, p, t, staged_.surface, inputs);
  use_with_inputs(atrous_program_, inputs, guide, staged_.surface);
  atrous_program_.set("k_l", atrous_k_l(p));
  const int passes = atrous_iterations(p.sigma_s);
  atrous_program_.bind(shared::kUnitSignal, inputs.hv());
  for (int i = 0; i < passes; ++i) {
    const bool last = i + 1 == passes;
    atrous_program_.set("step_px", 1 << i);
    atrous_program_.set("variance_correction", atrous_variance_correction(i));
    atrous_program_.set("final_pass", last ? 1 : 0);
    quad_.draw(atrous_program_, last ? fbo_ : scratch_target(i % 2), width_, height_);
    if (!last) atrous_program_.bind(shared::kUnitSignal, scratch_[i % 2]);
  }
}

// One pass over the tap table of (sigma_s, taps), uploaded again only when those change.
void FilterPass::run_subsampled(const PreviewInputs& inputs, const Texture2D& guide, const FilterParams& p, float t) {
  if (!subsampled_program_.id()) subsampled_program_ = Program::from_embedded("fullscreen.vert", "subsampled.frag");
  const int taps = p.subsampled_taps > 0 ? p.subsampled_taps : kSubsampledTaps;
  const SubsampledTapTable table = subsampled_tap_table(p.sigma_s, taps);
  if (subsampled_key_ != std::make_pair(p.sigma_s, taps) || !subsampled_taps_.id()) {
    const size_t bytes = table.taps.size() * sizeof(SubsampledTap);
    if (!subsampled_taps_.id()) subsampled_taps_ = Buffer(bytes);
    subsampled_taps_.upload(table.taps.data(), bytes);
    subsampled_key_ = {p.sigma_s, taps};
  }
  subsampled_taps_.bind_storage(shared::kBufferTaps);
  set_range_and_skip(subsampled_program_, p, t, staged_.surface, inputs);
  subsampled_program_.set("taps_per_rotation", table.per_rotation);
  subsampled_program_.set("rotations", kSubsampledRotations);
  use_with_inputs(subsampled_program_, inputs, guide, staged_.surface);
  quad_.draw(subsampled_program_, fbo_, width_, height_);
}

void FilterPass::prepare(FilterKind kind) {
  if (kind == FilterKind::Grid && !grid_) grid_ = std::make_unique<GridFilter>(width_, height_);
  if (kind == FilterKind::Atrous && !atrous_program_.id())
    atrous_program_ = Program::from_embedded("fullscreen.vert", "atrous.frag");
  if (kind == FilterKind::Subsampled && !subsampled_program_.id())
    subsampled_program_ = Program::from_embedded("fullscreen.vert", "subsampled.frag");
  // The bilateral variants' program is the constructor's.
}

const Framebuffer& FilterPass::scratch_target(int index) {
  if (!scratch_[index].valid()) {
    scratch_[index] = Texture2D(width_, height_, TextureFormat::RGBA32F);
    scratch_fbo_[index].attach(0, scratch_[index]);
    scratch_fbo_[index].check("filter pass (scratch)");
  }
  return scratch_fbo_[index];
}

uint32_t FilterPass::filtered_pixels() const {
  uint32_t n = 0;
  counter_.download(&n, sizeof n);
  return n;
}

Image FilterPass::centre_weight_image() const { return centre_weight_.download({"Y"}); }
Image FilterPass::filtered_image() const { return output_.download({"R", "G", "B"}); }

Image FilterPass::raw_variance_image() const {
  Image rgba = output_.download({"R", "G", "B", "A"});
  Image out = Image::gray(width_, height_);
  for (size_t i = 0; i < out.pixel_count(); ++i) out.pixels[i] = rgba.pixels[4 * i + 3];
  return out;
}

Image FilterPass::variance_image() const { return variance_from_alpha(output_); }

}  // namespace pxf
