#include "gl/tonemap_pass.h"

#include <cmath>
#include "gl/gl.h"

namespace pxf {

TonemapPass::TonemapPass(int width, int height)
    : width_(width), height_(height), program_(Program::from_embedded("fullscreen.vert", "tonemap.frag")),
      output_(width, height, TextureFormat::RGBA32F) {
  fbo_.attach(0, output_);
  fbo_.check("tone map pass");
}

void TonemapPass::run(const Texture2D& hdr, const TonemapParams& p) {
  if (hdr.width() != width_ || hdr.height() != height_) throw Error("tone map pass: input size differs from the pass size");
  timer_.begin();
  last_params_ = p;
  if (!(p.log_average > 0)) reduction_.run(hdr, 1, p.delta);
  program_.set("key", p.key);
  program_.set("white", p.white);
  program_.set("log_average", p.log_average > 0 ? p.log_average : 0.0f);
  reduction_.result_buffer().bind_storage(2);
  program_.use();
  program_.bind(0, hdr);
  quad_.draw(program_, fbo_, width_, height_);
  timer_.end();
  check_gl_error("tone map pass");
}

float TonemapPass::log_average() const {
  if (last_params_.log_average > 0) return last_params_.log_average;
  return std::exp(reduction_.read_sum() / (static_cast<float>(width_) * height_));
}

Image TonemapPass::display_image() const { return output_.download({"R", "G", "B"}); }

}  // namespace pxf
