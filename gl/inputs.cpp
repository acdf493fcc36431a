#include "gl/inputs.h"

namespace pxf {

PreviewInputs::PreviewInputs(int width, int height)
    : width_(width), height_(height), lv_(width, height, TextureFormat::RGBA32F),
      hv_(width, height, TextureFormat::RGBA32F), albedo_(width, height, TextureFormat::RGBA32F) {}

void PreviewInputs::upload_packed(const float* lv_rgb, const float* hv_rgba) {
  timer_.begin();
  lv_.upload(lv_rgb, 3);
  hv_.upload(hv_rgba, 4);
  has_halves_ = false;
  timer_.end();
}

void PreviewInputs::upload_packed_with_threshold(const float* lv_rgba, const float* hv_rgba) {
  timer_.begin();
  lv_.upload(lv_rgba, 4);
  hv_.upload(hv_rgba, 4);
  has_halves_ = false;
  timer_.end();
}

void PreviewInputs::upload(const float* lv_rgb, const float* hv_rgb, const float* var_of_mean) {
  const size_t n = static_cast<size_t>(width_) * height_;
  packed_.resize(n * 4);
  for (size_t i = 0; i < n; ++i) {
    packed_[4 * i + 0] = hv_rgb[3 * i + 0];
    packed_[4 * i + 1] = hv_rgb[3 * i + 1];
    packed_[4 * i + 2] = hv_rgb[3 * i + 2];
    packed_[4 * i + 3] = var_of_mean[i];
  }
  upload_packed(lv_rgb, packed_.data());
}

void PreviewInputs::upload(const Image& lv, const Image& hv, const Image& var) {
  for (const Image* im : {&lv, &hv, &var})
    if (im->width != width_ || im->height != height_) throw Error("preview inputs: image size differs from the textures");
  if ((lv.num_channels() != 3 && lv.num_channels() != 4) || hv.num_channels() != 3 || var.num_channels() != 1)
    throw Error("preview inputs: expected RGB (or RGBA) lv, RGB hv and a one-channel variance");
  if (lv.num_channels() == 3) {
    upload(lv.pixels.data(), hv.pixels.data(), var.pixels.data());
    return;
  }
  const size_t n = static_cast<size_t>(width_) * height_;
  packed_.resize(n * 4);
  for (size_t i = 0; i < n; ++i) {
    for (int c = 0; c < 3; ++c) packed_[4 * i + c] = hv.pixels[3 * i + c];
    packed_[4 * i + 3] = var.pixels[i];
  }
  upload_packed_with_threshold(lv.pixels.data(), packed_.data());
}

void PreviewInputs::upload_albedo(const float* albedo_rgb) { albedo_.upload(albedo_rgb, 3); }

void PreviewInputs::upload_albedo(const Image& albedo) {
  if (albedo.width != width_ || albedo.height != height_ || albedo.num_channels() != 3)
    throw Error("preview inputs: the albedo must be an RGB image of the textures' size");
  upload_albedo(albedo.pixels.data());
}

void PreviewInputs::upload_halves(const float* halves_rgba, const float* variances_rg) {
  timer_.begin();
  if (!halves_) {
    halves_ = std::make_unique<Texture2D>(width_, height_, TextureFormat::RGBA32F);
    half_variances_ = std::make_unique<Texture2D>(width_, height_, TextureFormat::RG32F);
  }
  halves_->upload(halves_rgba, 4);
  half_variances_->upload(variances_rg, 2);
  has_halves_ = true;
  timer_.end();
}

void PreviewInputs::upload_halves(const Image& halves, const Image& variances) {
  for (const Image* im : {&halves, &variances})
    if (im->width != width_ || im->height != height_)
      throw Error("preview inputs: image size differs from the textures");
  if (halves.num_channels() != 4 || variances.num_channels() != 2)
    throw Error("preview inputs: expected RGBA halves and two-channel half variances");
  upload_halves(halves.pixels.data(), variances.pixels.data());
}

Image PreviewInputs::lv_image() const { return lv_.download({"R", "G", "B"}); }
Image PreviewInputs::hv_image() const { return hv_.download({"R", "G", "B"}); }
Image PreviewInputs::albedo_image() const { return albedo_.download({"R", "G", "B"}); }
Image PreviewInputs::var_image() const {
  return variance_from_alpha(hv_);
}

}  // namespace pxf
