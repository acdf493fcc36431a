#include "app/explorer/explorer_views.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

#include "gl/gl.h"
#include "preview/adaptive.h"

namespace pxf {

namespace {

struct ViewInfo {
  BufferView view;
  const char* name;
  const char* label;
};

const ViewInfo kViews[kBufferViewCount] = {
    {BufferView::Final, "final", "1  final (tone-mapped)"},
    {BufferView::Lv, "lv", "2  LV (low variance)"},
    {BufferView::Hv, "hv", "3  HV unfiltered L_u"},
    {BufferView::HvFiltered, "hv-filtered", "4  HV filtered L_f"},
    {BufferView::RangeColor, "range", "5  range color"},
    {BufferView::Depth, "depth", "6  depth (distance)"},
    {BufferView::VarU, "var-u", "7  Var[L_u] (log)"},
    {BufferView::VarF, "var-f", "8  Var[L_f] (log)"},
    {BufferView::Blend, "blend", "9  blend factor s"},
    {BufferView::Case, "case", "0  blend case"},
    {BufferView::Unfiltered, "unfiltered", "   unfiltered L_lv + L_u"},
    {BufferView::Samples, "samples", "   paths per pixel"},
    {BufferView::Active, "active", "   next frame's active pixels"},
    {BufferView::History, "history", "   reprojected history"},
};

// The legend's colors are the case view's (shared::case_color, shaders/view_case.frag).
CaseStyle case_style(const char* label, int code) {
  const glm::vec3 c = shared::case_color(code);
  return {label, c.r, c.g, c.b};
}
const std::array<CaseStyle, kBlendCaseCount> kCaseStyles = {{
    case_style("0  no L_f yet (s = 1)", kCaseNoFiltered),
    case_style("1  least variance (mostly filtered)", kCaseLeastVariance),
    case_style("2  unfiltered (s = 1)", kCaseUnfiltered),
    case_style("3  mixed (0 < s < 1)", kCaseMixed),
    case_style("4  n < 2 (s = 0)", kCaseUnknownVar),
    case_style("5  bias guard (s raised)", kCaseBiasGuard),
}};

// Far apart in hue and lightness, and unlike the turbo scale's ends, so that the mask does not
// read as a scalar view: skipped pixels dark slate, traced ones bright amber.
const std::array<CaseStyle, 2> kActiveStyles = {{
    {"skipped by the next frame", 0.15f, 0.20f, 0.35f},
    {"traced by the next frame", 1.00f, 0.78f, 0.20f},
}};

constexpr int kLegendWidth = 256;

// The value at fraction q of the sorted values (q in [0,1]).
float percentile(std::vector<float>& values, double q) {
  const size_t k = std::min(values.size() - 1, static_cast<size_t>(q * (values.size() - 1)));
  std::nth_element(values.begin(), values.begin() + k, values.end());
  return values[k];
}

}  // namespace

const std::vector<std::string>& buffer_view_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (const ViewInfo& v : kViews) n.push_back(v.name);
    return n;
  }();
  return names;
}

const char* buffer_view_label(BufferView view) { return kViews[static_cast<int>(view)].label; }

BufferView parse_buffer_view(const std::string& name) {
  for (const ViewInfo& v : kViews)
    if (name == v.name) return v.view;
  std::string list;
  for (const ViewInfo& v : kViews) list += (list.empty() ? "" : ", ") + std::string(v.name);
  throw Error("unknown view '" + name + "' (valid: " + list + ")");
}

int buffer_view_of_digit(int digit) {
  if (digit < 0 || digit > 9) return -1;
  return digit == 0 ? 9 : digit - 1;
}

bool is_scalar_view(BufferView v) {
  return v == BufferView::VarU || v == BufferView::VarF || v == BufferView::Blend || v == BufferView::Depth ||
         v == BufferView::Samples;
}

const std::array<CaseStyle, kBlendCaseCount>& case_styles() { return kCaseStyles; }
const std::array<CaseStyle, 2>& active_styles() { return kActiveStyles; }

const std::array<CaseStyle, 4>& history_styles() {
  static const std::array<CaseStyle, 4> styles = {CaseStyle{"no history", 0.25f, 0.25f, 0.25f},
                                                  CaseStyle{"kept (weight: brighter)", 0.15f, 0.85f, 0.15f},
                                                  CaseStyle{"disoccluded", 0.95f, 0.20f, 0.15f},
                                                  CaseStyle{"outside the last view", 0.20f, 0.40f, 0.95f}};
  return styles;
}

Image history_view_colors(const Image& outcome, const Image& weight) {
  Image colors = Image::rgb(outcome.width, outcome.height);
  for (size_t p = 0; p < outcome.pixel_count(); ++p) {
    const int o = std::clamp(static_cast<int>(outcome.pixels[p]), 0, 3);
    const CaseStyle& c = history_styles()[o];
    const float shade = o == shared::kHistoryKept ? 0.25f + 0.75f * std::clamp(weight.pixels[p], 0.0f, 1.0f) : 1.0f;
    colors.pixels[3 * p + 0] = shade * c.r;
    colors.pixels[3 * p + 1] = shade * c.g;
    colors.pixels[3 * p + 2] = shade * c.b;
  }
  return colors;
}

double active_share(const std::vector<uint8_t>& active) {
  if (active.empty()) return 1.0;
  const auto untraced = std::count(active.begin(), active.end(), uint8_t{0});
  return static_cast<double>(active.size() - static_cast<size_t>(untraced)) / static_cast<double>(active.size());
}

std::string sampling_status_line(double case2_share, const SamplingSnapshot& sampling) {
  const SampleCounts counts = sample_counts(sampling.paths);  // the same figures stats.json reports
  char line[160];
  std::snprintf(line, sizeof line, "clean (case 2): %.1f %%   paths/pixel mean %.1f (min %u, max %u)   active %.1f %%",
                100.0 * case2_share, counts.mean, counts.min, counts.max, 100.0 * active_share(sampling.active));
  return line;
}

ViewRenderer::ViewRenderer(int width, int height)
    : width_(width),
      height_(height),
      scalar_(Program::from_embedded("fullscreen.vert", "view_scalar.frag")),
      case_(Program::from_embedded("fullscreen.vert", "view_case.frag")),
      display_(Program::from_embedded("fullscreen.vert", "view_display.frag")),
      split_(Program::from_embedded("fullscreen.vert", "view_split.frag")),
      split_output_(width, height, TextureFormat::RGBA8),
      legend_ramp_(kLegendWidth, 1, TextureFormat::R32F),
      legend_output_(kLegendWidth, 1, TextureFormat::RGBA8),
      hdr_tonemap_(width, height),
      unfiltered_(width, height),
      samples_(width, height, TextureFormat::R32F),
      active_(width, height, TextureFormat::RGBA8), history_(width, height, TextureFormat::RGBA32F) {
  for (int i = 0; i < 3; ++i) {
    outputs_[i] = Texture2D(width, height, TextureFormat::RGBA8);
    outputs_[i].set_filter(false);  // magnified views show pixels, not blur
    output_fbos_[i].attach(0, outputs_[i]);
    output_fbos_[i].check("explorer view");
  }
  split_output_.set_filter(false);
  split_fbo_.attach(0, split_output_);
  split_fbo_.check("explorer split view");
  legend_output_.set_filter(true);
  legend_fbo_.attach(0, legend_output_);
  legend_fbo_.check("explorer legend");
  scale(BufferView::Blend) = ScalarScale{0.0f, 1.0f, /*log=*/false, /*automatic=*/false};
  scale(BufferView::Depth) = ScalarScale{0.0f, 10.0f, /*log=*/false, /*automatic=*/true};
  scale(BufferView::VarU) = ScalarScale{1e-6f, 1.0f, /*log=*/true, /*automatic=*/true};
  scale(BufferView::VarF) = ScalarScale{1e-6f, 1.0f, /*log=*/true, /*automatic=*/true};
  // Linear: an adaptive render's counts span about one decade (a pixel is traced between every
  // 16th frame and every frame), and a linear scale reads directly as paths.
  scale(BufferView::Samples) = ScalarScale{0.0f, 1.0f, /*log=*/false, /*automatic=*/true};
}

void ViewRenderer::set_sampling(SamplingSnapshot sampling) {
  sampling_ = std::move(sampling);
  sampling_uploaded_ = false;
  // No read-back here, only a pass over the counts: the automatic scale follows every snapshot, so
  // the legend's ends are the image's fewest and most paths (the status line's min and max).
  set_samples_scale();
}

void ViewRenderer::set_samples_scale() {
  // The whole range, not percentiles: counts have no outliers to hide, and the few pixels at the
  // most or fewest paths are the ones to see. Equal counts sit mid-scale on a range of one path.
  ScalarScale& s = scale(BufferView::Samples);
  if (!s.automatic || sampling_.paths.empty()) return;
  const SampleCounts c = sample_counts(sampling_.paths);
  s.lo = c.min == c.max ? c.min - 0.5f : static_cast<float>(c.min);
  s.hi = c.min == c.max ? c.max + 0.5f : static_cast<float>(c.max);
}

void ViewRenderer::upload_sampling() {
  if (sampling_uploaded_) return;
  const size_t pixels = static_cast<size_t>(width_) * height_;
  std::vector<float> paths(pixels, 0.0f);
  if (sampling_.paths.size() == pixels) std::copy(sampling_.paths.begin(), sampling_.paths.end(), paths.begin());
  samples_.upload(paths.data(), 1);
  const bool every_pixel = sampling_.active.size() != pixels;  // empty: adaptive off or still warming up
  std::vector<unsigned char> rgba(4 * pixels);
  for (size_t p = 0; p < pixels; ++p) {
    const CaseStyle& c = kActiveStyles[every_pixel || sampling_.active[p] > 0 ? 1 : 0];
    rgba[4 * p + 0] = static_cast<unsigned char>(std::lround(255.0f * c.r));
    rgba[4 * p + 1] = static_cast<unsigned char>(std::lround(255.0f * c.g));
    rgba[4 * p + 2] = static_cast<unsigned char>(std::lround(255.0f * c.b));
    rgba[4 * p + 3] = 255;
  }
  active_.upload_rgba8(rgba.data());
  sampling_uploaded_ = true;
}

void ViewRenderer::draw_scalar(const Texture2D& source, int channel, const ScalarScale& s, bool sentinels,
                               float background, const Framebuffer& target, int width, int height) {
  scalar_.set("channel", channel);
  scalar_.set("log_scale", s.log ? 1 : 0);
  scalar_.set("lo", s.lo);
  scalar_.set("hi", s.hi);
  scalar_.set("sentinels", sentinels ? 1 : 0);
  scalar_.set("background", background);
  scalar_.use();
  scalar_.bind(0, source);
  quad_.draw(scalar_, target, width, height);
}

void ViewRenderer::draw_display(const Texture2D& source, bool encode_srgb, int slot) {
  display_.set("encode_srgb", encode_srgb ? 1 : 0);
  display_.use();
  display_.bind(0, source);
  quad_.draw(display_, output_fbos_[slot], width_, height_);
}

void ViewRenderer::tonemap_like_final(const Texture2D& hdr, Preview& preview, int slot) {
  // Same key and the final image's log-average: HDR buffers compare at the same exposure.
  TonemapParams params = preview.settings().tonemap;
  if (!(params.log_average > 0)) params.log_average = preview.tonemap().log_average();
  hdr_tonemap_.run(hdr, params);
  draw_display(hdr_tonemap_.output(), false, slot);
}

const Texture2D& ViewRenderer::render(BufferView view, Preview& preview, int slot) {
  const Framebuffer& target = output_fbos_[slot];
  const Texture2D* filtered = preview.has_filtered() ? &preview.filtered_output() : nullptr;
  switch (view) {
    case BufferView::Final: draw_display(preview.tonemap().output(), false, slot); break;
    case BufferView::Lv: tonemap_like_final(preview.inputs().lv(), preview, slot); break;
    case BufferView::Hv: tonemap_like_final(preview.inputs().hv(), preview, slot); break;
    case BufferView::HvFiltered:  // without an L_f yet the blend uses L_u: show that
      tonemap_like_final(filtered ? *filtered : preview.inputs().hv(), preview, slot);
      break;
    case BufferView::Unfiltered:
      unfiltered_.run(preview.inputs(), nullptr, nullptr, preview.settings().threshold, BlendParams{});
      tonemap_like_final(unfiltered_.output(), preview, slot);
      break;
    case BufferView::RangeColor:
      preview.converge_range_buffer();
      draw_display(preview.range().guide(), true, slot);
      break;
    case BufferView::Depth:
      preview.converge_range_buffer();
      draw_scalar(preview.range().guide(), 3, scale(view), false, kBackgroundDepth * 0.5f, target, width_, height_);
      break;
    case BufferView::VarU:
      draw_scalar(preview.inputs().hv(), 3, scale(view), true, 0.0f, target, width_, height_);
      break;
    case BufferView::VarF:
      if (filtered) {
        draw_scalar(*filtered, 3, scale(view), true, 0.0f, target, width_, height_);
      } else {  // no L_f: every Var[L_f] unknown (the sentinel's color)
        const float unknown[4] = {0.25f, 0.25f, 0.25f, 1.0f};
        glClearNamedFramebufferfv(target.id(), GL_COLOR, 0, unknown);
      }
      break;
    case BufferView::Blend:
      draw_scalar(preview.blend().output(), 3, scale(view), false, 0.0f, target, width_, height_);
      break;
    case BufferView::Case:
      case_.use();
      case_.bind(0, preview.blend().case_texture());
      quad_.draw(case_, target, width_, height_);
      break;
    case BufferView::Samples:  // CPU data: the snapshot, not the preview (set_sampling)
      upload_sampling();
      draw_scalar(samples_, 0, scale(view), false, 0.0f, target, width_, height_);
      break;
    case BufferView::Active:  // colors made on the CPU, copied as they are
      upload_sampling();
      draw_display(active_, false, slot);
      break;
    case BufferView::History: {  // colors made on the CPU from two read-backs
      const HistoryPass* history = preview.history();
      const bool shown = history && history->reprojected() && preview.history_active();
      const Image colors = shown ? history_view_colors(history->outcome_image(), history->weight_image())
                                 : Image::rgb(width_, height_, history_styles()[0].r);
      history_.upload(colors);
      draw_display(history_, false, slot);
      break;
    }
  }
  check_gl_error("explorer view");
  return outputs_[slot];
}

const Texture2D& ViewRenderer::split(const Texture2D& left, const Texture2D& right, float divider) {
  split_.set("divider", divider);
  split_.use();
  split_.bind(0, left);
  split_.bind(1, right);
  quad_.draw(split_, split_fbo_, width_, height_);
  check_gl_error("explorer split view");
  return split_output_;
}

const Texture2D& ViewRenderer::legend(BufferView view) {
  const ScalarScale& s = scale(view);
  std::vector<float> ramp(kLegendWidth);
  for (int i = 0; i < kLegendWidth; ++i) {
    const float x = (i + 0.5f) / kLegendWidth;
    ramp[i] = s.log ? std::pow(10.0f, std::log10(std::max(s.lo, 1e-30f)) * (1 - x) + std::log10(std::max(s.hi, 1e-30f)) * x)
                    : s.lo + (s.hi - s.lo) * x;
  }
  legend_ramp_.upload(ramp.data(), 1);
  draw_scalar(legend_ramp_, 0, s, false, 0.0f, legend_fbo_, kLegendWidth, 1);
  return legend_output_;
}

void ViewRenderer::update_auto_scale(BufferView view, Preview& preview) {
  ScalarScale& s = scale(view);
  if (!s.automatic || !is_scalar_view(view) || view == BufferView::Blend) return;
  if (view == BufferView::Samples) return set_samples_scale();
  Image source;
  if (view == BufferView::VarU) source = preview.inputs().var_image();
  else if (view == BufferView::VarF && preview.has_filtered()) source = preview.filtered_variance_image();
  else if (view == BufferView::Depth) source = preview.range().depth_image();
  else return;
  std::vector<float> values;
  values.reserve(source.pixels.size());
  for (float v : source.pixels) {
    const bool usable = std::isfinite(v) && (view == BufferView::Depth ? v < kBackgroundDepth * 0.5f : v > 0.0f);
    if (usable) values.push_back(v);
  }
  if (values.empty()) return;
  if (view == BufferView::Depth) {
    // Percentiles: antialiased silhouettes against the background average in huge distances.
    s.lo = percentile(values, 0.01);
    s.hi = std::max(percentile(values, 0.99), s.lo + 1e-3f);
  } else {  // a decade-aligned log range covering the middle 98%
    s.lo = std::pow(10.0f, std::floor(std::log10(percentile(values, 0.01))));
    s.hi = std::pow(10.0f, std::ceil(std::log10(percentile(values, 0.99))));
    if (s.hi <= s.lo) s.hi = s.lo * 10.0f;
  }
}

}  // namespace pxf
