// The explorer's buffer views (issue 6): every buffer of the preview rendered into a display
// texture (tone-mapped, false color, case colors), split views and legends. GL only, no ImGui,
// so the views can be tested headless.
// Usage:
//   ViewRenderer views(w, h);
//   const Texture2D& shown = views.render(BufferView::VarU, preview, /*slot=*/0);
//   const Texture2D& both = views.split(views.render(a, preview, 0), views.render(b, preview, 1), x);
#pragma once
#include <array>
#include <string>
#include <vector>

#include "app/preview.h"
#include "gl/blend_pass.h"
#include "gl/resources.h"
#include "gl/tonemap_pass.h"

namespace pxf {

// In the order of the number keys 1..9, 0; Unfiltered (L_lv + L_u) has no key.
enum class BufferView { Final, Lv, Hv, HvFiltered, RangeColor, Depth, VarU, VarF, Blend, Case, Unfiltered };
constexpr int kBufferViewCount = 11;

// Command-line names ("final", "lv", "hv", "hv-filtered", "range", "depth", "var-u", "var-f",
// "blend", "case", "unfiltered") and UI labels.
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
bool is_scalar_view(BufferView view);  // VarU, VarF, Blend, Depth

// Colors of the case view, also for its legend: index = case code (kCase*).
struct CaseStyle {
  const char* label;
  float r, g, b;
};
const std::array<CaseStyle, kBlendCaseCount>& case_styles();

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
  // Sets the automatic scales of the view from the preview's buffer (a read-back: call now and then).
  void update_auto_scale(BufferView view, Preview& preview);

 private:
  void draw_scalar(const Texture2D& source, int channel, const ScalarScale& scale, bool sentinels, float background,
                   const Framebuffer& target, int width, int height);
  void draw_display(const Texture2D& source, bool encode_srgb, int slot);
  void tonemap_like_final(const Texture2D& hdr, Preview& preview, int slot);

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
};

}  // namespace pxf
