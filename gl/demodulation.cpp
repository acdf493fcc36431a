#include "gl/demodulation.h"

#include "gl/gl.h"

namespace pxf {

Demodulation::Demodulation(int width, int height)
    : width_(width), height_(height), demod_program_(Program::from_embedded("fullscreen.vert", "demodulate.frag")),
      remod_program_(Program::from_embedded("fullscreen.vert", "remodulate.frag")), filter_inputs_(width, height),
      output_(width, height, TextureFormat::RGBA32F) {
  demod_fbo_.attach(0, filter_inputs_.hv());
  demod_fbo_.attach(1, filter_inputs_.lv());
  demod_fbo_.check("demodulation");
  remod_fbo_.attach(0, output_);
  remod_fbo_.check("remodulation");
}

void Demodulation::demodulate(const PreviewInputs& inputs, const Texture2D& guide, const FilterParams& p, float t,
                              const Texture2D* surface) {
  if (inputs.width() != width_ || inputs.height() != height_ || guide.width() != width_ || guide.height() != height_)
    throw Error("demodulation: input size differs from the pass size");
  demod_timer_.begin();
  const RangeWeights range = range_weights(p);
  demod_program_.set("k_c", range.k_c);
  demod_program_.set("k_d", range.k_d);
  demod_program_.set("k_n", surface ? range.k_n : 0.0f);
  demod_program_.set("k_r", surface ? range.k_r : 0.0f);
  demod_program_.set("t", t);
  demod_program_.set("skip_case2", filter_skip_mode(p, inputs.has_halves()));
  demod_program_.use();
  demod_program_.bind(shared::kUnitHv, inputs.hv());
  demod_program_.bind(shared::kUnitLv, inputs.lv());
  demod_program_.bind(shared::kUnitGuide, guide);
  demod_program_.bind(shared::kUnitSurface, surface ? *surface : guide);
  demod_program_.bind(shared::kUnitAlbedo, inputs.albedo());
  demod_program_.bind(shared::kUnitHalfVariances, inputs.half_variances());
  quad_.draw(demod_program_, demod_fbo_, width_, height_);
  demod_timer_.end();
  check_gl_error("demodulation");
}

void Demodulation::remodulate(const Texture2D& filtered, const PreviewInputs& inputs) {
  if (filtered.width() != width_ || filtered.height() != height_ || inputs.width() != width_ ||
      inputs.height() != height_)
    throw Error("remodulation: input size differs from the pass size");
  remod_timer_.begin();
  remod_program_.use();
  remod_program_.bind(shared::kUnitFiltered, filtered);
  remod_program_.bind(shared::kUnitAlbedo, inputs.albedo());
  quad_.draw(remod_program_, remod_fbo_, width_, height_);
  remod_timer_.end();
  check_gl_error("remodulation");
}

Image Demodulation::filtered_image() const { return output_.download({"R", "G", "B"}); }

Image Demodulation::variance_image() const {
  return variance_from_alpha(output_);
}

}  // namespace pxf
