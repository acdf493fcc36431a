#include "gl/history_pass.h"

#include <cmath>

#include "gl/gl.h"

namespace pxf {

shared::ViewCamera view_camera(const Camera& camera, int width, int height) {
  shared::ViewCamera c;
  c.origin = glm::vec3(camera.camera_to_world[3]);
  c.basis = glm::mat3(camera.camera_to_world);
  c.half_height = camera.orthographic ? camera.ymag : std::tan(0.5f * camera.yfov);
  // As camera_ray: the image size wins over the glTF aspect ratio.
  c.aspect = height > 0 ? static_cast<float>(width) / static_cast<float>(height) : 1.0f;
  c.size = glm::vec2(static_cast<float>(width), static_cast<float>(height));
  c.orthographic = camera.orthographic;
  return c;
}

namespace {

void copy_texture(const Texture2D& from, const Texture2D& to) {
  glCopyImageSubData(from.id(), GL_TEXTURE_2D, 0, 0, 0, 0, to.id(), GL_TEXTURE_2D, 0, 0, 0, 0, from.width(),
                     from.height(), 1);
}

void set_camera_uniforms(const Program& program, const std::string& prefix, const shared::ViewCamera& c) {
  program.set((prefix + "_origin").c_str(), c.origin);
  program.set((prefix + "_basis").c_str(), c.basis);
  program.set((prefix + "_half_height").c_str(), c.half_height);
  program.set((prefix + "_aspect").c_str(), c.aspect);
  program.set((prefix + "_orthographic").c_str(), c.orthographic ? 1 : 0);
}

}  // namespace

HistoryPass::HistoryPass(int width, int height)
    : width_(width), height_(height),
      reproject_program_(Program::from_embedded("fullscreen.vert", "history_reproject.frag")),
      combine_program_(Program::from_embedded("fullscreen.vert", "history_combine.frag")),
      normals_program_(Program::from_embedded("fullscreen.vert", "history_normals.frag")),
      kept_lv_(width, height, TextureFormat::RGBA32F), kept_hv_(width, height, TextureFormat::RGBA32F),
      kept_guide_(width, height, TextureFormat::RGBA32F), kept_normals_(width, height, TextureFormat::RGBA32F),
      normals_(width, height, TextureFormat::RGBA32F), history_lv_(width, height, TextureFormat::RGBA32F),
      history_hv_(width, height, TextureFormat::RGBA32F), outcome_(width, height, TextureFormat::R32F),
      combined_(width, height), state_(width, height, TextureFormat::RGBA32F),
      weight_(width, height, TextureFormat::R32F) {
  kept_normals_fbo_.attach(0, kept_normals_);
  kept_normals_fbo_.check("history normals");
  normals_fbo_.attach(0, normals_);
  normals_fbo_.check("history normals");
  reproject_fbo_.attach(0, history_lv_);
  reproject_fbo_.attach(1, history_hv_);
  reproject_fbo_.attach(2, outcome_);
  reproject_fbo_.check("history reprojection");
  combine_fbo_.attach(0, combined_.lv());
  combine_fbo_.attach(1, combined_.hv());
  combine_fbo_.attach(2, state_);
  combine_fbo_.attach(3, weight_);
  combine_fbo_.check("history combination");
}

void HistoryPass::keep(const PreviewInputs& fresh, float samples, const Texture2D& guide,
                       const Texture2D& specular_flags, const Camera& camera) {
  if (fresh.width() != width_ || fresh.height() != height_ || guide.width() != width_ || guide.height() != height_)
    throw Error("history pass: input size differs from the pass size");
  if (!(active(samples) && combined_since_reprojection_)) run_combine(fresh, samples, false);
  timer_.begin();
  copy_texture(state_, kept_lv_);
  copy_texture(combined_.hv(), kept_hv_);
  copy_texture(guide, kept_guide_);
  compute_normals(kept_guide_, specular_flags, camera, kept_normals_fbo_);
  kept_camera_ = camera;
  has_kept_ = true;
  last_ms_ = timer_.end();
  total_ms_ += last_ms_;
  check_gl_error("history keep");
}

void HistoryPass::reproject(const Texture2D& guide, const Texture2D& specular_flags, const Camera& camera) {
  if (!has_kept_) return;
  if (guide.width() != width_ || guide.height() != height_)
    throw Error("history pass: guide size differs from the pass size");
  timer_.begin();
  compute_normals(guide, specular_flags, camera, normals_fbo_);
  reproject_program_.use();
  set_camera_uniforms(reproject_program_, "now", view_camera(camera, width_, height_));
  set_camera_uniforms(reproject_program_, "before", view_camera(kept_camera_, width_, height_));
  reproject_program_.bind(shared::kUnitHistoryLv, kept_lv_);
  reproject_program_.bind(shared::kUnitHistoryHv, kept_hv_);
  reproject_program_.bind(shared::kUnitHistoryGuide, kept_guide_);
  reproject_program_.bind(shared::kUnitHistoryNormals, kept_normals_);
  reproject_program_.bind(shared::kUnitGuide, guide);
  reproject_program_.bind(shared::kUnitNormals, normals_);
  quad_.draw(reproject_program_, reproject_fbo_, width_, height_);
  last_ms_ = timer_.end();
  total_ms_ += last_ms_;
  check_gl_error("history reprojection");
  reprojected_ = true;
  combined_since_reprojection_ = false;
}

void HistoryPass::compute_normals(const Texture2D& guide, const Texture2D& specular_flags, const Camera& camera,
                                  const Framebuffer& target) {
  if (specular_flags.width() != width_ || specular_flags.height() != height_)
    throw Error("history pass: specular flags' size differs from the pass size");
  normals_program_.use();
  set_camera_uniforms(normals_program_, "cam", view_camera(camera, width_, height_));
  normals_program_.bind(shared::kUnitGuide, guide);
  normals_program_.bind(shared::kUnitSignal, specular_flags);
  quad_.draw(normals_program_, target, width_, height_);
}

void HistoryPass::run_combine(const PreviewInputs& fresh, float samples, bool with_history) {
  if (fresh.width() != width_ || fresh.height() != height_)
    throw Error("history pass: input size differs from the pass size");
  timer_.begin();
  combine_program_.use();
  combine_program_.set("samples", samples);
  combine_program_.set("has_history", with_history ? 1 : 0);
  combine_program_.bind(shared::kUnitHv, fresh.hv());
  combine_program_.bind(shared::kUnitLv, fresh.lv());
  combine_program_.bind(shared::kUnitHistoryLv, history_lv_);
  combine_program_.bind(shared::kUnitHistoryHv, history_hv_);
  quad_.draw(combine_program_, combine_fbo_, width_, height_);
  last_ms_ = timer_.end();
  total_ms_ += last_ms_;
  check_gl_error("history combination");
}

const PreviewInputs& HistoryPass::combine(const PreviewInputs& fresh, float samples) {
  run_combine(fresh, samples, reprojected_);
  combined_since_reprojection_ = reprojected_;
  return combined_;
}

void HistoryPass::drop() { has_kept_ = reprojected_ = combined_since_reprojection_ = false; }

Image HistoryPass::outcome_image() const { return outcome_.download({"Y"}); }
Image HistoryPass::weight_image() const { return weight_.download({"Y"}); }
Image HistoryPass::history_lv_image() const { return history_lv_.download({"R", "G", "B", "A"}); }
Image HistoryPass::history_hv_image() const { return history_hv_.download({"R", "G", "B", "A"}); }

Image history_outcome_colors(const Image& outcome) {
  Image colors = Image::rgb(outcome.width, outcome.height);
  for (size_t p = 0; p < outcome.pixels.size(); ++p) {
    const int o = static_cast<int>(outcome.pixels[p]);
    colors.pixels[3 * p + 0] = o == shared::kHistoryDisoccluded ? 1.0f : 0.0f;
    colors.pixels[3 * p + 1] = o == shared::kHistoryKept ? 0.8f : 0.0f;
    colors.pixels[3 * p + 2] = o == shared::kHistoryOutside ? 1.0f : 0.0f;
  }
  return colors;
}

}  // namespace pxf
