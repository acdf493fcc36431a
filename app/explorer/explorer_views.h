// The explorer's buffer views: every buffer of the preview rendered into a display
// texture (tone-mapped, false color, case colors), split views and legends. GL only, no ImGui,
// so the views can be tested headless.
// Usage:
//   ViewRenderer views(w, h);
//   const Texture2D& shown = views.render(BufferView::VarU, preview, /*slot=*/0);
//   const Texture2D& both = views.split(views.render(a, preview, 0), views.render(b, preview, 1), x);
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "gl/blend_pass.h"
#include "gl/resources.h"
#include "gl/tonemap_pass.h"
#include "preview/preview.h"

namespace pxf {

// In the order of the number keys 1..9, 0; Unfiltered (L_lv + L_u), Samples (paths traced into
// each pixel), Active (the next frame's adaptive mask) and History (the reprojected
// history after a camera move: kept with its weight, disoccluded, outside) have no key.
enum class BufferView { Final, Lv, Hv, HvFiltered, RangeColor, Depth, VarU, VarF, Blend, Case, Unfiltered, Samples, Active,
                        History };
constexpr int kBufferViewCount = 14;

// Command-line names ("final", "lv", "hv", "hv-filtered", "range", "depth", "var-u", "var-f",
// "blend", "case", "unfiltered", "samples", "active", "history") and UI labels.
const std::vector<std::string>& buffer_view_names();
const char* buffer_view_label(BufferView view);
BufferView parse_buffer_view(const std::string& name);  // throws pxf::Error listing the names
// The view of number key '1'..'9', '0'; -1 for another key.
int buffer_view_of_digit(int digit);

// How a scalar view maps values to colors (and its legend's tick labels).
struct ScalarScale {
  float lo = 1e-6f, hi = 1.0f;
  bool log = true;
  bool automatic = true;  // follow the image's range (percentiles), updated now and then
};
bool is_scalar_view(BufferView view);  // VarU, VarF, Blend, Depth, Samples

// Colors of the case view, also for its legend: index = case code (kCase*).
struct CaseStyle {
  const char* label;
  float r, g, b;
};
const std::array<CaseStyle, kBlendCaseCount>& case_styles();
// Colors of the active view, also for its legend: [0] skipped by the next frame, [1] traced.
const std::array<CaseStyle, 2>& active_styles();
// Colors of the history view, also for its legend: index = kHistory* (shaders/history_formulas.h);
// a kept pixel's green is darker where the history's weight in the shown image is lower.
const std::array<CaseStyle, 4>& history_styles();
// The history view's colors ("R,G,B") from HistoryPass::outcome_image and weight_image.
Image history_view_colors(const Image& outcome, const Image& weight);

// Adaptive sampling per pixel, copied from the preview while it is not tracing: the
// explorer's worker writes the per-pixel counts during a frame, so the samples and active views
// and the status line read this copy (taken after each traced frame) instead of the live vectors.
struct SamplingSnapshot {
  std::vector<uint32_t> paths;  // Preview::pixel_samples(): paths traced into each pixel, row-major, top row first
  std::vector<uint8_t> active;  // Preview::next_active(): paths the next frame traces in each pixel; empty = one in every pixel
  static SamplingSnapshot of(const Preview& preview) { return {preview.pixel_samples(), preview.next_active()}; }
};
// The share of the pixels the next frame traces: 1 when the mask is empty (every pixel).
double active_share(const std::vector<uint8_t>& active);
// The explorer's status line of adaptive sampling:
// "clean (case 2): X.X %   paths/pixel mean M (min a, max b)   active Y.Y %" with the case-2 share
// of the last blend (Preview::case2_share()) and the active share of the next frame.
std::string sampling_status_line(double case2_share, const SamplingSnapshot& sampling);

class ViewRenderer {
 public:
  ViewRenderer(int width, int height);

  // Renders `view` of the preview's current state into display texture `slot` (0..2, RGBA8,
  // nearest filtering) and returns it.
  const Texture2D& render(BufferView view, Preview& preview, int slot);
  // Left of `divider` (pixels) from `left`, right of it from `right`.
  const Texture2D& split(const Texture2D& left, const Texture2D& right, float divider);
  // A 256x1 color ramp of the scale of a scalar view (same shader as the view).
  const Texture2D& legend(BufferView view);

  // The explorer's frame: renders the view (or the split of two views) into the texture that
  // shown(split) returns; the texture object stays the same, so the UI can refer to it before.
  void show(BufferView view, Preview& preview) { render(view, preview, 0); }
  void show_split(BufferView left, BufferView right, float divider, Preview& preview) {
    split(render(left, preview, 0), render(right, preview, 1), divider);
  }
  const Texture2D& shown(bool split) const { return split ? split_output_ : outputs_[0]; }

  ScalarScale& scale(BufferView view) { return scales_[static_cast<int>(view)]; }
  // Sets the automatic scales of the view from the preview's buffer (a read-back: call now and then;
  // the samples view's follows set_sampling by itself).
  void update_auto_scale(BufferView view, Preview& preview);

  // The per-pixel data of the samples and active views (and of the explorer's status line): the
  // caller copies it from the preview while the preview is not tracing (SamplingSnapshot::of);
  // uploaded when one of those views is next rendered, and the samples view's automatic scale set
  // from it. Until the first call both views show an empty snapshot: 0 paths, every pixel active.
  void set_sampling(SamplingSnapshot sampling);
  const SamplingSnapshot& sampling() const { return sampling_; }

 private:
  void draw_scalar(const Texture2D& source, int channel, const ScalarScale& scale, bool sentinels, float background,
                   const Framebuffer& target, int width, int height);
  void draw_display(const Texture2D& source, bool encode_srgb, int slot);
  void tonemap_like_final(const Texture2D& hdr, Preview& preview, int slot);
  void upload_sampling();  // the snapshot into samples_ and active_, if it changed
  void set_samples_scale();  // the automatic scale of the samples view from the snapshot

  int width_, height_;
  Program scalar_, case_, display_, split_;
  std::array<Texture2D, 3> outputs_;
  std::array<Framebuffer, 3> output_fbos_;
  Texture2D split_output_, legend_ramp_, legend_output_;
  Framebuffer split_fbo_, legend_fbo_;
  TonemapPass hdr_tonemap_;  // HDR buffers with the final image's key and log-average
  BlendPass unfiltered_;     // without L_f the blend is L_lv + L_u
  FullscreenPass quad_;
  std::array<ScalarScale, kBufferViewCount> scales_;
  SamplingSnapshot sampling_;
  bool sampling_uploaded_ = false;
  Texture2D samples_;  // R32F: paths per pixel as floats (exact below 2^24)
  Texture2D active_;   // RGBA8: active_styles() colors, drawn as they are
  Texture2D history_;  // RGBA32F: history_view_colors, drawn as they are
};

}  // namespace pxf
