// The reprojected history of a moving camera (docs/method.md section 4.1): when the camera moves,
// what the previous view showed (its inputs, with the history it held itself, and their sample
// counts) is kept with that view's guide and camera, reprojected into the new view through the new
// guide's distance, rejected where the two guides disagree (disocclusion), and blended beside the
// new view's fresh samples as a second, biased estimate whose weight falls to 0 as fresh samples
// accumulate (shared::combine_history).
// Usage:
//   HistoryPass history(w, h);
//   history.keep(inputs_now, n, range.guide(), range.frame_color(), old_camera);  // before the camera changes
//   ... new camera, range.step() ...
//   history.reproject(range.guide(), range.frame_color(), new_camera);
//   after each upload of the fresh inputs (n samples):
//   const PreviewInputs& in = history.active(n) ? history.combine(fresh, n) : fresh;
#pragma once
#include "gl/inputs.h"
#include "gl/resources.h"
#include "scene/scene.h"
#include "shaders/history_formulas.h"

namespace pxf {

// A camera as the history formulas see it (camera_ray's terms) for an image of width x height.
shared::ViewCamera view_camera(const Camera& camera, int width, int height);

// The reprojection's outcome (HistoryPass::outcome_image) as colors: kept green, disoccluded red,
// outside the previous view blue, no history black.
Image history_outcome_colors(const Image& outcome);

class HistoryPass {
 public:
  HistoryPass(int width, int height);

  // Keeps the view's estimate for the next reprojection: the inputs last combined (combine()) if
  // there were any since the last reprojection, else `fresh` itself with `samples` samples per pixel.
  // guide: that view's range buffer; camera: its camera. A view that was never kept leaves the
  // previous one kept (a camera that moves on before a frame was traced).
  // specular_flags: the view's newest raster frame (RangePass::frame_color, a the specular flag).
  void keep(const PreviewInputs& fresh, float samples, const Texture2D& guide, const Texture2D& specular_flags,
            const Camera& camera);
  bool has_kept() const { return has_kept_; }
  // Reprojects the kept view into `camera`'s, whose range buffer is `guide`.
  void reproject(const Texture2D& guide, const Texture2D& specular_flags, const Camera& camera);
  // Whether a reprojected history still has weight after `samples` fresh samples.
  bool active(float samples) const { return reprojected_ && shared::history_count_kept(1.0f, samples) > 0.0f; }
  // The fresh inputs with the history beside them (shared::combine_history), for the filter and blend.
  const PreviewInputs& combine(const PreviewInputs& fresh, float samples);
  const PreviewInputs& combined() const { return combined_; }
  PreviewInputs& combined() { return combined_; }  // (its albedo, for demodulation)
  // Whether combine() ran since the last reprojection: combined() is then the current view's.
  bool has_combination() const { return combined_since_reprojection_; }
  // Forgets everything (a new scene, new path-tracing settings: the history is another render's).
  void drop();
  double last_ms() const { return last_ms_; }    // the last keep, reprojection or combination
  double total_ms() const { return total_ms_; }  // all of them since construction

  // For the views and tests: per pixel the reprojection's outcome (kHistory*, "Y"), the history's
  // weight in the last combination ("Y"), and the reprojected history (rgba L_lv + count, L_u + Var).
  Image outcome_image() const;
  Image weight_image() const;
  Image history_lv_image() const;  // "R,G,B,A": L_lv, the samples it holds
  Image history_hv_image() const;  // "R,G,B,A": L_u, Var[L_u]
  bool reprojected() const { return reprojected_; }

 private:
  void run_combine(const PreviewInputs& fresh, float samples, bool with_history);

  int width_, height_;
  // guide_normal of `guide` seen by `camera` into `normals`.
  void compute_normals(const Texture2D& guide, const Texture2D& specular_flags, const Camera& camera,
                       const Framebuffer& target);

  Program reproject_program_, combine_program_, normals_program_;
  // The kept view: its state (rgb L_lv, a count), L_u + Var, guide, camera.
  Texture2D kept_lv_, kept_hv_, kept_guide_, kept_normals_, normals_;
  Framebuffer kept_normals_fbo_, normals_fbo_;
  Camera kept_camera_;
  // The reprojected history in the new view, and what the reprojection found.
  Texture2D history_lv_, history_hv_, outcome_;
  // The combination: inputs for the passes, the state to keep, the history's weight.
  PreviewInputs combined_;
  Texture2D state_, weight_;
  Framebuffer reproject_fbo_, combine_fbo_;
  FullscreenPass quad_;
  StageTimer timer_;
  bool has_kept_ = false, reprojected_ = false, combined_since_reprojection_ = false;
  double last_ms_ = 0, total_ms_ = 0;
};

}  // namespace pxf
