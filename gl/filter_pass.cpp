#include "gl/filter_pass.h"

#include <algorithm>
#include <cmath>
#include "gl/gl.h"

namespace pxf {

FilterPass::FilterPass(int width, int height)
    : width_(width), height_(height), program_(Program::from_embedded("fullscreen.vert", "bilateral.frag")),
      output_(width, height, TextureFormat::RGBA32F), counter_(sizeof(uint32_t)) {
  fbo_.attach(0, output_);
  fbo_.check("filter pass");
}

void FilterPass::run(const PreviewInputs& inputs, const Texture2D& guide, const FilterParams& p) {
  if (inputs.width() != width_ || inputs.height() != height_ || guide.width() != width_ || guide.height() != height_)
    throw Error("filter pass: input size differs from the pass size");
  timer_.begin();
  const int radius = std::min(kMaxFilterRadius, static_cast<int>(std::ceil(3.0f * std::max(p.sigma_s, 0.0f))));
  program_.set("radius", radius);
  program_.set("k_s", inv_two_sigma2(p.sigma_s));
  const RangeWeights range = range_weights(p);
  program_.set("k_c", range.k_c);
  program_.set("k_d", range.k_d);
  program_.set("skip_case2", p.skip_case2 ? 1 : 0);
  program_.set("t", p.t);
  const uint32_t zero = 0;
  counter_.upload(&zero, sizeof zero);
  counter_.bind_storage(0);
  inputs.hv().bind(0);
  inputs.lv().bind(1);
  guide.bind(2);
  program_.use();
  if (p.kind == FilterKind::Separable) {
    if (!rows_.valid()) {
      rows_ = Texture2D(width_, height_, TextureFormat::RGBA32F);
      rows_fbo_.attach(0, rows_);
      rows_fbo_.check("filter pass (rows)");
    }
    program_.set("extent", glm::ivec2(1, 0));
    program_.set("final_pass", 0);
    inputs.hv().bind(3);
    quad_.draw(rows_fbo_, width_, height_);
    program_.set("extent", glm::ivec2(0, 1));
    rows_.bind(3);
  } else {
    program_.set("extent", glm::ivec2(1, 1));
    inputs.hv().bind(3);
  }
  program_.set("final_pass", 1);
  quad_.draw(fbo_, width_, height_);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
  timer_.end();
  ++runs_;
  check_gl_error("filter pass");
}

uint32_t FilterPass::filtered_pixels() const {
  uint32_t n = 0;
  counter_.download(&n, sizeof n);
  return n;
}

Image FilterPass::filtered_image() const { return output_.download({"R", "G", "B"}); }

Image FilterPass::raw_variance_image() const {
  Image rgba = output_.download({"R", "G", "B", "A"});
  Image out = Image::gray(width_, height_);
  for (size_t i = 0; i < out.pixel_count(); ++i) out.pixels[i] = rgba.pixels[4 * i + 3];
  return out;
}

Image FilterPass::variance_image() const {
  Image out = raw_variance_image();
  for (float& v : out.pixels) v = v > 0 ? v : 0.0f;
  return out;
}

}  // namespace pxf
