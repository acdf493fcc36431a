#include "app/explorer/explorer.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <deque>
#include <future>
#include <memory>
#include <vector>

#include "app/camera_path.h"
#include "scene/camera_controls.h"
#include "app/explorer/explorer_views.h"
#include "app/render_output.h"
#include "gl/context.h"
#include "gl/gl.h"
#include "preview/frame_budget.h"
#include "preview/pixel_probe.h"
#include "preview/preview.h"
#include "preview/setting_table.h"
#include "scene/auto_camera.h"
#include "scene/load.h"
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <imgui.h>
#include <imgui_stdlib.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>

namespace pxf {

namespace {

using Clock = std::chrono::steady_clock;

constexpr float kPanelWidth = 430.0f;
constexpr double kTraceBudgetMs = 30.0;  // path tracing per displayed frame when it is fast
// A GL step's predicted cost is its last one; the same step varies by about a third from frame to
// frame, so the budget counts it this much larger.
constexpr double kPredictionMargin = 1.3;
constexpr size_t kPlotLength = 600;
constexpr float kDividerGrabPixels = 6.0f;

// Scene files dropped onto the window since the last frame (GLFW calls back from glfwPollEvents).
std::vector<std::string> g_dropped_paths;
void on_drop(GLFWwindow*, int count, const char** paths) {
  for (int i = 0; i < count; ++i) g_dropped_paths.emplace_back(paths[i]);
}

double ms_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

// The default framebuffer (window plus UI) as an sRGB PNG-ready image, top row first.
Image read_window(int width, int height) {
  std::vector<unsigned char> rgba(static_cast<size_t>(width) * height * 4);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
  glReadBuffer(GL_BACK);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
  Image image = Image::rgb(width, height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      for (int c = 0; c < 3; ++c)  // GL rows go bottom-up
        image.at(x, y, c) = rgba[(static_cast<size_t>(height - 1 - y) * width + x) * 4 + c] / 255.0f;
  return image;
}

std::string variance_text(float v) {
  char text[64];
  if (v == kVarSkipped) return "skipped (case 2)";
  if (v < 0) return "unknown";
  std::snprintf(text, sizeof(text), "%.4g", v);
  return text;
}

class Explorer {
 public:
  Explorer(ExploreOptions& options, GlContext& context)
      : options_(options), context_(context), window_(static_cast<GLFWwindow*>(context.native_window())) {
    settings_ = options_.preview;
    view_ = parse_buffer_view(options_.view);
    if (!options_.split.empty()) {
      split_ = true;
      split_left_ = view_;
      split_right_ = parse_buffer_view(options_.split);
    }
    out_dir_ = options_.out;
    load(options_.scene.scene, /*first=*/true);
    views_ = std::make_unique<ViewRenderer>(preview_->width(), preview_->height());
    divider_ = 0.5f * width_;
    init_imgui();
  }
  ~Explorer() {
    stop_tracing(/*cancel=*/true);
    ImGui_ImplOpenGL3_Shutdown();
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
  }

  int run() {
    started_ = Clock::now();
    for (int frame = 0; !context_.should_close(); ++frame) {
      const auto frame_start = Clock::now();
      frame_start_ = frame_start;
      frame_gl_work_ = false;
      glfwPollEvents();
      load_dropped_scenes();
      // Tracing and its passes before the panel is built: the status line and the case legend
      // then count the blend the views below show, not the one before it.
      trace();
      ImGui_ImplOpenGL3_NewFrame();
      ImGui_ImplGlfw_NewFrame();
      ImGui::NewFrame();
      image_window();
      panel();
      handle_keys();
      apply_changes();
      const auto draw_start = Clock::now();
      render_views();
      ImGui::Render();
      draw_to_window();
      recent_ui_draw_ms_[frame % recent_ui_draw_ms_.size()] = ms_between(draw_start, Clock::now());
      ui_draw_ms_ = *std::max_element(recent_ui_draw_ms_.begin(), recent_ui_draw_ms_.end());
      // --frames (tests): not before the --spp / --time capture is finished.
      const bool run_done =
          (options_.spp <= 0 && options_.time_s <= 0) || (finished_ && !tracing_ && !preview_->passes_pending());
      const bool last = options_.frames > 0 && frame + 1 >= options_.frames && run_done;
      // The longest display frame before the swap (which may wait for vsync), from the third
      // traced frame on: the first runs of each pass include compiling its shaders. Before the
      // last frame's capture and screenshot, which are not a display frame's work.
      if (frames_traced_ > 2) longest_frame_ms_ = std::max(longest_frame_ms_, ms_between(frame_start, Clock::now()));
      if (last) finish_run();
      context_.present();
      if (last) break;
    }
    return 0;
  }

 private:
  // --- scene ---------------------------------------------------------------------------------
  void load(const std::string& path, bool first) {
    stop_tracing(/*cancel=*/true);
    try {
      auto scene = std::make_unique<Scene>(load_scene(path, first ? options_.scene.env : "", options_.scene.env_strength,
                                                      parse_default_light(options_.scene.default_light),
                                                      load_limits(options_.scene)));
      print_scene_messages(*scene);
      if (!options_.all_hv_given) settings_.trace.all_hv = scene->defaults.all_hv;
      if (!options_.filter_given)
        settings_.filter.kind = takes_all_hv_filter(*scene, settings_) ? kAllHvFilter : options_.preview.filter.kind;
      if (first) size_image(*scene);
      if (scene->automatic_camera) scene->camera = frame_scene(*scene, static_cast<float>(width_) / height_);
      auto preview = std::make_unique<Preview>(*scene, settings_, width_, height_);
      controller_ = std::make_unique<CameraController>(scene->camera, scene_bounds(*scene));
      if (first && !options_.camera_path.empty()) {
        path_ = camera_path_for(options_.camera_path, *scene);
        path_frame_ = 0;
        playing_path_ = camera_changed_ = true;
      }
      preview_ = std::move(preview);  // the old preview goes before its scene
      scene_ = std::move(scene);
      options_.scene.scene = path;
      scene_error_.clear();
      history_.clear();
      if (views_) views_->set_sampling(SamplingSnapshot::of(*preview_));
    } catch (const Error& e) {
      if (first) throw;
      scene_error_ = e.what();  // keep the previous scene running
      std::fprintf(stderr, "pxf explore: %s\n", e.what());
    }
  }

  void size_image(const Scene& scene) {
    width_ = options_.scene.width, height_ = options_.scene.height;
    if (width_ == 0) {
      width_ = scene.defaults.width > 0 ? scene.defaults.width : 512;
      height_ = scene.defaults.height > 0 ? scene.defaults.height : 512;
    }
  }

  void load_dropped_scenes() {
    std::vector<std::string> paths;
    paths.swap(g_dropped_paths);
    for (const std::string& p : paths) load(p, false);
  }

  // --- ImGui set-up and window ---------------------------------------------------------------
  void init_imgui() {
    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini in the working directory
    ImGui::StyleColorsDark();
    ImGui_ImplGlfw_InitForOpenGL(window_, true);
    ImGui_ImplOpenGL3_Init("#version 450");
    glfwSetDropCallback(window_, on_drop);
  }

  float zoom(float area_w, float area_h) const {
    if (options_.zoom > 0) return static_cast<float>(options_.zoom);
    const float fit = std::min(area_w / width_, area_h / height_);
    return fit >= 1.0f ? std::floor(fit) : fit;  // integer magnification keeps pixels square
  }

  // The image at the top-left of the window, at an integer zoom when it fits.
  void image_window() {
    const ImGuiIO& io = ImGui::GetIO();
    const float area_w = io.DisplaySize.x - kPanelWidth, area_h = io.DisplaySize.y;
    ImGui::SetNextWindowPos(ImVec2(0, 0));
    ImGui::SetNextWindowSize(ImVec2(area_w, area_h));
    ImGui::PushStyleVar(ImGuiStyleVar_WindowPadding, ImVec2(0, 0));
    ImGui::PushStyleVar(ImGuiStyleVar_WindowBorderSize, 0.0f);
    ImGui::Begin("image", nullptr,
                 ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoBringToFrontOnFocus |
                     ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoScrollWithMouse);
    scale_ = zoom(area_w, area_h);
    const ImVec2 size(width_ * scale_, height_ * scale_);
    const ImVec2 origin = ImGui::GetCursorScreenPos();
    ImGui::InvisibleButton("canvas", size,
                           ImGuiButtonFlags_MouseButtonLeft | ImGuiButtonFlags_MouseButtonRight |
                               ImGuiButtonFlags_MouseButtonMiddle);
    const bool hovered = ImGui::IsItemHovered(), active = ImGui::IsItemActive();
    ImGui::GetWindowDrawList()->AddImage(texture_id(shown_texture()), origin,
                                         ImVec2(origin.x + size.x, origin.y + size.y));
    mouse_on_image(origin, hovered, active);
    if (hovered && inspector_ && !active) {
      inspector_tooltip(static_cast<int>((io.MousePos.x - origin.x) / scale_),
                        static_cast<int>((io.MousePos.y - origin.y) / scale_));
    } else if (options_.inspect_x >= 0) {  // pinned from the command line
      ImGui::SetNextWindowPos(ImVec2(origin.x + (options_.inspect_x + 1) * scale_ + 16, origin.y + options_.inspect_y * scale_));
      inspector_tooltip(options_.inspect_x, options_.inspect_y);
    }
    ImGui::End();
    ImGui::PopStyleVar(2);
  }

  static ImTextureID texture_id(const Texture2D& t) { return reinterpret_cast<ImTextureID>(static_cast<intptr_t>(t.id())); }

  const Texture2D& shown_texture() { return views_->shown(split_); }

  void mouse_on_image(const ImVec2& origin, bool hovered, bool active) {
    const ImGuiIO& io = ImGui::GetIO();
    const float divider_screen = origin.x + divider_ * scale_;
    if (split_ && hovered && ImGui::IsMouseClicked(ImGuiMouseButton_Left) &&
        std::abs(io.MousePos.x - divider_screen) <= kDividerGrabPixels)
      dragging_divider_ = true;
    if (!ImGui::IsMouseDown(ImGuiMouseButton_Left)) dragging_divider_ = false;
    if (dragging_divider_) {
      divider_ = std::clamp((io.MousePos.x - origin.x) / scale_, 0.0f, static_cast<float>(width_));
      return;
    }
    if (active && (io.MouseDelta.x != 0 || io.MouseDelta.y != 0)) {
      if (ImGui::IsMouseDown(ImGuiMouseButton_Left)) controller_->orbit(io.MouseDelta.x, io.MouseDelta.y);
      else controller_->pan(io.MouseDelta.x, io.MouseDelta.y, height_ * scale_);
      camera_changed_ = true;
    }
    if (hovered && io.MouseWheel != 0) {
      controller_->zoom(io.MouseWheel);
      camera_changed_ = true;
    }
    dragging_camera_ = active;
  }

  // Magnifier (nearest-neighbour crop of the shown view) and every buffer's value at the cursor.
  void inspector_tooltip(int x, int y) {
    if (x < 0 || y < 0 || x >= width_ || y >= height_) return;
    const PixelProbe p = probe_pixel(*preview_, samples_snapshot_, x, y);
    ImGui::BeginTooltip();
    constexpr float kHalf = 8.0f;
    const ImVec2 uv0((x - kHalf) / width_, (y - kHalf) / height_), uv1((x + kHalf + 1) / width_, (y + kHalf + 1) / height_);
    const ImVec2 at = ImGui::GetCursorScreenPos();
    ImGui::Image(texture_id(shown_texture()), ImVec2(153, 153), uv0, uv1);
    const float cell = 153.0f / (2 * kHalf + 1);  // outline the pixel under the cursor
    ImGui::GetWindowDrawList()->AddRect(ImVec2(at.x + kHalf * cell, at.y + kHalf * cell),
                                        ImVec2(at.x + (kHalf + 1) * cell, at.y + (kHalf + 1) * cell), IM_COL32(255, 255, 255, 255));
    ImGui::Text("pixel (%d, %d)   n = %u", p.x, p.y, p.n);
    const SamplingSnapshot& sampling = views_->sampling();
    const size_t i = static_cast<size_t>(y) * width_ + x;
    if (i < sampling.paths.size())
      ImGui::Text("paths %u   next frame: %s", sampling.paths[i],
                  sampling.active.size() > i && sampling.active[i] == 0 ? "skipped" : "traced");
    ImGui::Text("final     %.4g %.4g %.4g", p.final_s.r, p.final_s.g, p.final_s.b);
    if (p.blended) blend_decision_lines(p.blend);
    else ImGui::TextDisabled("(not blended yet)");
    ImGui::Text("range     %.3f %.3f %.3f   depth %.4g", p.guide.r, p.guide.g, p.guide.b, p.guide.a);
    material_lines(p.surface);
    ImGui::EndTooltip();
  }

  // The material under the pixel and the lobes its BSDF samples there (ProgressiveRenderer::surface_material).
  static void material_lines(const SurfaceMaterial& m) {
    if (!m.hit) {
      ImGui::TextDisabled("material  (none: the environment)");
      return;
    }
    ImGui::Text("material  %s", m.material.c_str());
    ImGui::Text("  base %.3f %.3f %.3f  metallic %.2f  roughness %.2f", m.base_color.r, m.base_color.g, m.base_color.b,
                m.metallic, m.roughness);
    if (m.transmission > 0.0f) ImGui::Text("  transmission %.2f  ior %.3f", m.transmission, m.ior);
    if (m.clearcoat > 0.0f) ImGui::Text("  clearcoat %.2f  roughness %.2f", m.clearcoat, m.clearcoat_roughness);
    if (m.sheen_color != glm::vec3(0.0f))
      ImGui::Text("  sheen %.3f %.3f %.3f  roughness %.2f", m.sheen_color.r, m.sheen_color.g, m.sheen_color.b, m.sheen_roughness);
    if (m.emission != glm::vec3(0.0f)) ImGui::Text("  emission %.4g %.4g %.4g", m.emission.r, m.emission.g, m.emission.b);
    std::string lobes = "  lobes";
    for (const SurfaceLobe& lobe : m.lobes) {
      char part[64];
      std::snprintf(part, sizeof part, "  %s %.2f%s", lobe.name.c_str(), lobe.probability, lobe.delta ? " (delta)" : "");
      lobes += part;
    }
    ImGui::TextUnformatted(m.lobes.empty() ? "  lobes  none (black)" : lobes.c_str());
  }

  // The blend's inputs and decision at the pixel, as the last blend run made them (pooled u, the
  // pixel's threshold t_n, s, f and the case: BlendPass::inspect).
  static void blend_decision_lines(const BlendInspection& blend) {
    const shared::BlendTexels& px = blend.texels;
    const shared::BlendPixel& d = blend.decision;
    ImGui::Text("LV        %.4g %.4g %.4g", px.lv.r, px.lv.g, px.lv.b);
    ImGui::Text("HV L_u    %.4g %.4g %.4g", px.hv.r, px.hv.g, px.hv.b);
    if (blend.switches.has_filtered) ImGui::Text("HV L_f    %.4g %.4g %.4g", px.filtered.r, px.filtered.g, px.filtered.b);
    else ImGui::TextDisabled("HV L_f    (filter has not run)");
    const bool compared = shared::blend_compares_variances(px, blend.switches);
    if (compared && blend.switches.has_guide)
      ImGui::Text("Var[L_u]  %s   pooled %s", variance_text(px.hv.a).c_str(), variance_text(d.var_u).c_str());
    else ImGui::Text("Var[L_u]  %s", variance_text(px.hv.a).c_str());
    ImGui::Text("Var[L_f]  %s", blend.switches.has_filtered ? variance_text(px.filtered.a).c_str() : "-");
    if (compared) ImGui::Text("u %.4g   f %.4g   L_b %.4g", d.u, d.f, d.lb);
    else ImGui::Text("L_b %.4g   (u, f not compared)", d.lb);
    const int code = d.blend_case;
    ImGui::Text("t_n %.4g   s %.4f", d.t, d.s);
    ImGui::Text("case %s", code >= 0 && code < kBlendCaseCount ? case_styles()[code].label : "?");
  }

  // --- the panel ------------------------------------------------------------------------------
  void panel() {
    const ImGuiIO& io = ImGui::GetIO();
    ImGui::SetNextWindowPos(ImVec2(io.DisplaySize.x - kPanelWidth, 0));
    ImGui::SetNextWindowSize(ImVec2(kPanelWidth, io.DisplaySize.y));
    ImGui::Begin("pxf explorer", nullptr, ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse);
    ImGui::PushItemWidth(200);
    status_section();
    view_section();
    comparison_section();
    parameter_section();
    camera_section();
    capture_section();
    scene_section();
    ImGui::PopItemWidth();
    ImGui::End();
  }

  void status_section() {
    if (!ImGui::CollapsingHeader("Status", ImGuiTreeNodeFlags_DefaultOpen)) return;
    const int pixels = width_ * height_;
    ImGui::Text("%d spp%s   %dx%d   %.2f Mpaths/s", preview_->samples(),
                options_.spp > 0 && preview_->samples() >= options_.spp ? " (done)" : (paused_ ? " (paused)" : ""),
                width_, height_, paths_per_second_ / 1e6);
    ImGui::Text("ms: trace %.1f/frame  range %.1f  filter %.1f", stage_ms_.path_tracing, stage_ms_.range,
                preview_->filter().last_ms());
    ImGui::Text("    longest display frame %.0f ms (budget %.0f; tracing on a worker)", longest_frame_ms_, kUiBudgetMs);
    ImGui::Text("    blend %.2f  tone map %.2f   filter runs %d (sigma s %.2f)%s", stage_ms_.blend, stage_ms_.tonemap,
                preview_->filter_runs(), preview_->last_sigma_s(),
                preview_->filter_stopped() ? " (stopped: all case 2)" : "");
    const auto& counts = preview_->shown_case_counts();  // the views' blend, also right after a move
    shown_case_counts_ = counts;
    std::string cases = "cases";  // every case code, so a new case cannot be left out of the line
    for (int c = 0; c < kBlendCaseCount; ++c) {
      char part[32];
      std::snprintf(part, sizeof part, "  %d: %.1f%%", c, 100.0 * counts[c] / pixels);
      cases += part;
    }
    ImGui::TextUnformatted(cases.c_str());
    ImGui::TextWrapped("%s", sampling_status_line(preview_->case2_share(), views_->sampling()).c_str());  // wider than the panel
    const std::vector<float> plot(history_.begin(), history_.end());
    char overlay[64];
    std::snprintf(overlay, sizeof(overlay), "pixels at s = 1: %.1f%%", plot.empty() ? 0.0 : 100.0 * plot.back());
    ImGui::PlotLines("##s1", plot.data(), static_cast<int>(plot.size()), 0, overlay, 0.0f, 1.0f,
                     ImVec2(kPanelWidth - 30, 60));
    if (!scene_error_.empty()) ImGui::TextColored(ImVec4(1, 0.35f, 0.3f, 1), "%s", scene_error_.c_str());
    if (!status_message_.empty()) ImGui::TextWrapped("%s", status_message_.c_str());
  }

  void view_section() {
    if (!ImGui::CollapsingHeader("Buffer view (keys 1-0)", ImGuiTreeNodeFlags_DefaultOpen)) return;
    // Every view without a scrollbar: the rows plus the child's own padding above and below.
    ImGui::BeginChild("views",
                      ImVec2(0, kBufferViewCount * ImGui::GetTextLineHeightWithSpacing() + 2 * ImGui::GetStyle().WindowPadding.y),
                      true);
    for (int i = 0; i < kBufferViewCount; ++i)
      if (ImGui::Selectable(buffer_view_label(BufferView(i)), view_ == BufferView(i))) view_ = BufferView(i);
    ImGui::EndChild();
    legend(split_ ? split_left_ : view_);
    if (split_ && split_right_ != split_left_) legend(split_right_);
  }

  void legend(BufferView view) {
    if (view == BufferView::Case) {
      const auto& counts = preview_->shown_case_counts();
      for (int c = 0; c < kBlendCaseCount; ++c) {
        const CaseStyle& style = case_styles()[c];
        ImGui::ColorButton(style.label, ImVec4(style.r, style.g, style.b, 1), ImGuiColorEditFlags_NoTooltip, ImVec2(14, 14));
        ImGui::SameLine();
        ImGui::Text("%-26s %5.1f%%", style.label, 100.0 * counts[c] / (width_ * height_));
      }
      return;
    }
    if (view == BufferView::Active) {
      const SamplingSnapshot& sampling = views_->sampling();
      const double traced = active_share(sampling.active);
      for (int a = 1; a >= 0; --a) {
        const CaseStyle& style = active_styles()[a];
        ImGui::ColorButton(style.label, ImVec4(style.r, style.g, style.b, 1), ImGuiColorEditFlags_NoTooltip, ImVec2(14, 14));
        ImGui::SameLine();
        ImGui::Text("%-26s %5.1f%%", style.label, 100.0 * (a == 1 ? traced : 1.0 - traced));
      }
      if (sampling.active.empty())
        ImGui::TextDisabled(settings_.adaptive ? "uniform warm-up: every pixel is traced" : "adaptive sampling off (--adaptive on)");
      return;
    }
    if (view == BufferView::History) {
      for (const CaseStyle& style : history_styles()) {
        ImGui::ColorButton(style.label, ImVec4(style.r, style.g, style.b, 1), ImGuiColorEditFlags_NoTooltip, ImVec2(14, 14));
        ImGui::SameLine();
        ImGui::TextUnformatted(style.label);
      }
      if (!preview_->history_active()) ImGui::TextDisabled("no history with weight (the camera rests, or --motion-history off)");
      return;
    }
    if (!is_scalar_view(view)) return;
    ScalarScale& s = views_->scale(view);
    ImGui::TextUnformatted(buffer_view_label(view) + 3);
    const float w = kPanelWidth - 30;
    ImGui::Image(texture_id(views_->legend(view)), ImVec2(w, 14));
    const char* format = s.log ? "%.0e" : "%.3g";
    char lo[32], mid[32], hi[32];
    std::snprintf(lo, sizeof(lo), format, s.lo);
    std::snprintf(mid, sizeof(mid), format, s.log ? std::sqrt(s.lo * s.hi) : 0.5f * (s.lo + s.hi));
    std::snprintf(hi, sizeof(hi), format, s.hi);
    ImGui::TextUnformatted(lo);
    ImGui::SameLine(w * 0.5f - ImGui::CalcTextSize(mid).x * 0.5f);
    ImGui::TextUnformatted(mid);
    ImGui::SameLine(w - ImGui::CalcTextSize(hi).x);
    ImGui::TextUnformatted(hi);
    if (view == BufferView::VarU || view == BufferView::VarF)
      ImGui::TextDisabled("log scale; dark gray: unknown (n < 2)%s", view == BufferView::VarF ? ", light: skipped" : "");
    if (view == BufferView::Depth) ImGui::TextDisabled("scene units; black: no surface");
    if (view == BufferView::Samples) ImGui::TextDisabled("paths traced into each pixel, linear");
    if (view == BufferView::Blend) return;
    ImGui::PushID(static_cast<int>(view));
    ImGui::Checkbox("auto range", &s.automatic);
    if (!s.automatic) {
      ImGui::SameLine();
      ImGui::SetNextItemWidth(120);
      ImGui::DragFloat("lo", &s.lo, s.log ? 0.0f : 0.01f * (s.hi - s.lo), 0, 0, "%.3g");
      ImGui::SameLine();
      ImGui::SetNextItemWidth(120);
      ImGui::DragFloat("hi", &s.hi, s.log ? 0.0f : 0.01f * (s.hi - s.lo), 0, 0, "%.3g");
      if (s.log) {  // decade steps
        if (ImGui::SmallButton("lo /10")) s.lo /= 10;
        ImGui::SameLine();
        if (ImGui::SmallButton("lo x10")) s.lo = std::min(s.lo * 10, s.hi);
        ImGui::SameLine();
        if (ImGui::SmallButton("hi /10")) s.hi = std::max(s.hi / 10, s.lo);
        ImGui::SameLine();
        if (ImGui::SmallButton("hi x10")) s.hi *= 10;
      }
    }
    ImGui::PopID();
  }

  void view_combo(const char* label, BufferView* view) {
    int index = static_cast<int>(*view);
    ImGui::Combo(label, &index, [](void*, int i, const char** text) { *text = buffer_view_label(BufferView(i)); return true; },
                 nullptr, kBufferViewCount);
    *view = BufferView(index);
  }

  void comparison_section() {
    if (!ImGui::CollapsingHeader("Comparison", ImGuiTreeNodeFlags_DefaultOpen)) return;
    ImGui::Checkbox("split view (drag the divider)", &split_);
    if (split_) {
      view_combo("left", &split_left_);
      view_combo("right", &split_right_);
      ImGui::SliderFloat("divider", &divider_, 0.0f, static_cast<float>(width_), "%.0f px");
    }
    if (ImGui::Button("filtered vs unfiltered")) {
      split_ = true;
      split_left_ = BufferView::Final;
      split_right_ = BufferView::Unfiltered;
    }
    ImGui::SameLine();
    ImGui::Checkbox("magnifier / inspector", &inspector_);
  }

  void parameter_section() {
    if (!ImGui::CollapsingHeader("Parameters", ImGuiTreeNodeFlags_DefaultOpen)) return;
    PreviewSettings& s = settings_;
    bool changed = false;
    for (const SettingDescriptor& d : setting_table()) changed |= setting_widget(d, s);
    ImGui::Checkbox("pause", &paused_);
    ImGui::SameLine();
    ImGui::SetNextItemWidth(120);
    ImGui::InputInt("stop at spp", &options_.spp, 0);
    options_.spp = std::max(options_.spp, 0);
    settings_changed_ |= changed;
  }

  // The widget of one setting (preview/setting_table.h): its label, range and kind come from its descriptor.
  static bool setting_widget(const SettingDescriptor& d, PreviewSettings& s) {
    const SettingWidget& w = d.widget;
    if (*w.label == '\0') return false;
    const ImGuiSliderFlags flags = w.logarithmic ? ImGuiSliderFlags_Logarithmic : 0;
    switch (d.type) {
      case SettingType::Float:
        return ImGui::SliderFloat(w.label, &d.float_field(s), static_cast<float>(w.min), static_cast<float>(w.max), w.format, flags);
      case SettingType::Int:
        return ImGui::SliderInt(w.label, &d.int_field(s), static_cast<int>(w.min), static_cast<int>(w.max), w.format, flags);
      case SettingType::Switch:
        return ImGui::Checkbox(w.label, &d.switch_field(s));
      case SettingType::Choice: {
        size_t index = d.choice_index(s);
        if (!enum_combo(w.label, *d.names, &index)) return false;
        d.set_choice_index(s, index);
        return true;
      }
      case SettingType::Seed:
        return false;  // no widget: a new seed is a new render, set on the command line
    }
    return false;
  }

  // A combo box over an enum's name table (names[i] names static_cast<E>(i), as on the command line).
  template <typename E>
  static bool enum_combo(const char* label, const std::vector<std::string>& names, E* value) {
    bool changed = false;
    const size_t current = static_cast<size_t>(*value);
    if (ImGui::BeginCombo(label, current < names.size() ? names[current].c_str() : "?")) {
      for (size_t i = 0; i < names.size(); ++i)
        if (ImGui::Selectable(names[i].c_str(), i == current) && i != current) {
          *value = static_cast<E>(i);
          changed = true;
        }
      ImGui::EndCombo();
    }
    return changed;
  }

  void camera_section() {
    if (!ImGui::CollapsingHeader("Camera")) return;
    ImGui::TextWrapped("left drag: orbit   right/middle drag: pan   wheel: zoom   WASD: fly, Q/E: down/up "
                       "(Shift: faster)   R: reset");
    if (ImGui::Button("reset camera (R)")) reset_camera();
    ImGui::SameLine();
    ImGui::Checkbox("skip filter while moving", &fast_while_moving_);
  }

  void capture_section() {
    if (!ImGui::CollapsingHeader("Capture", ImGuiTreeNodeFlags_DefaultOpen)) return;
    ImGui::InputText("folder", &out_dir_);
    if (ImGui::Button("save view + buffers (P)")) capture();
  }

  void scene_section() {
    if (!ImGui::CollapsingHeader("Scene")) return;
    ImGui::TextWrapped("%s", options_.scene.scene.c_str());
    ImGui::InputText("path", &scene_path_);
    ImGui::SameLine();
    if (ImGui::Button("load")) load(scene_path_, false);
    ImGui::TextDisabled("or drop a .gltf/.glb onto the window");
  }

  // --- input and state ------------------------------------------------------------------------
  void handle_keys() {
    const ImGuiIO& io = ImGui::GetIO();
    if (io.WantTextInput) return;
    for (int digit = 0; digit <= 9; ++digit)
      if (ImGui::IsKeyPressed(GLFW_KEY_0 + digit, false)) view_ = BufferView(buffer_view_of_digit(digit));
    if (ImGui::IsKeyPressed(GLFW_KEY_R, false)) reset_camera();
    if (ImGui::IsKeyPressed(GLFW_KEY_P, false)) capture();
    glm::vec3 fly(0.0f);
    if (ImGui::IsKeyDown(GLFW_KEY_W)) fly.z += 1;
    if (ImGui::IsKeyDown(GLFW_KEY_S)) fly.z -= 1;
    if (ImGui::IsKeyDown(GLFW_KEY_D)) fly.x += 1;
    if (ImGui::IsKeyDown(GLFW_KEY_A)) fly.x -= 1;
    if (ImGui::IsKeyDown(GLFW_KEY_E)) fly.y += 1;
    if (ImGui::IsKeyDown(GLFW_KEY_Q)) fly.y -= 1;
    if (fly != glm::vec3(0.0f)) {
      controller_->fly(fly * (io.KeyShift ? 4.0f : 1.0f), std::min(io.DeltaTime, 0.1f));
      camera_changed_ = true;
    }
    flying_ = fly != glm::vec3(0.0f);
  }

  void reset_camera() {
    controller_->reset();
    camera_changed_ = true;
  }

  // Camera moves reset the accumulation. With the reprojected history (docs/method.md 4.1) the
  // view keeps what it showed and the filter keeps running; a move waits for the frame being
  // traced, whose samples the history then carries into the new view. Without it a move cancels
  // that frame (it would be discarded anyway), and "skip filter while moving" leaves the filter out
  // until the camera rests. Other changes wait for the frame and the queued passes, without blocking.
  void apply_changes() {
    if (camera_changed_ && tracing_ && !settings_.motion_history) stop_tracing(/*cancel=*/true);
    if (tracing_ || preview_->passes_pending()) return;
    const bool camera = camera_changed_;
    if (camera_changed_) {
      // With the history a camera change is GL work of its own (the view kept), and it queues two
      // steps that run_passes spreads over display frames like any pass (the new view's range
      // frame, the reprojection) before the view's first traced frame. Like a queued pass it waits
      // for a later display frame when its last cost does not fit what is left of this one's
      // budget. A display frame that waited for no traced frame and ran no pass always takes it;
      // the next one is such a frame, since no frame is traced while a camera change waits.
      if (settings_.motion_history &&
          !step_fits_display_frame(ms_between(frame_start_, Clock::now()) + ui_draw_ms_, !frame_gl_work_,
                                   kPredictionMargin * camera_change_ms_))
        return;
      const auto start = Clock::now();
      preview_->begin_camera_change(playing_path_ ? camera_on_path(path_, path_frame_, scene_->camera)
                                                  : controller_->camera());
      camera_change_ms_ = ms_between(start, Clock::now());
    }
    camera_changed_ = false;
    const bool moving = fast_while_moving_ && (dragging_camera_ || flying_ || playing_path_);
    const bool settings = settings_changed_ || moving != applied_moving_;
    if (settings) {
      PreviewSettings effective = settings_;
      if (moving) effective.filter.kind = FilterKind::None;
      preview_->set_settings(effective);
      settings_changed_ = false;
      applied_moving_ = moving;
    }
    // Either may have reset the samples (and cleared the mask): the views show the reset at once.
    if (camera || settings) views_->set_sampling(SamplingSnapshot::of(*preview_));
  }

  bool spp_reached() const {
    if (options_.spp > 0 && preview_->samples() >= options_.spp) return true;
    if (options_.time_s <= 0 || preview_->samples() == 0) return false;
    const double elapsed = ms_between(accumulation_start_, Clock::now());
    return !next_frame_fits(preview_->predict_next_frame(options_.time_s * 1000.0, elapsed));
  }

  // --- tracing on a worker thread, GL passes within the frame budget (preview/frame_budget.h) ------
  // The UI thread never waits for a whole path-traced frame: the tracer runs on a worker, and
  // each display frame waits at most kTraceBudgetMs for it (so small images still get several
  // frames per display frame), then runs the GL steps that fit in kUiBudgetMs. Tracing and the GL
  // passes never overlap, as in `pxf render`, so the samples, schedule and buffers are the same.
  void start_trace() {
    tracing_ = true;
    trace_result_ = std::async(std::launch::async, [this] { return preview_->trace_frame(); });
  }

  // Waits for the worker (cancelled first if asked: it then stops within a few tiles).
  void stop_tracing(bool cancel) {
    if (!tracing_) return;
    if (cancel) preview_->cancel_trace();
    const bool complete = trace_result_.get();
    tracing_ = false;
    if (complete) frame_traced();
  }

  void frame_traced() {
    ++frames_traced_;
    const int samples = preview_->samples();
    const bool last = options_.spp > 0 && samples == options_.spp;
    preview_->queue_passes(last, /*display=*/true);
    // After queue_passes: it plans the next frame's mask. The worker is idle until the next
    // start_trace, so the per-pixel counts can be copied now (the views must not read them live).
    views_->set_sampling(SamplingSnapshot::of(*preview_));
    finished_ = last;
    samples_snapshot_ = preview_->renderer().accumulation().samples;
    ++frames_since_display_;
    frame_stats_pending_ = true;  // averaged once its passes have run
  }

  // Runs queued GL steps while they fit in the budget (ui_ms of this display frame already used).
  void run_passes(double used_ms, bool fresh) {
    double gl_ms = 0;  // of the steps run
    for (int steps = 0; preview_->passes_pending(); ++steps) {
      if (!step_fits_display_frame(used_ms + gl_ms + ui_draw_ms_, fresh && steps == 0,
                                   kPredictionMargin * preview_->predict_pass_ms(preview_->next_pass())))
        break;
      const auto start = Clock::now();
      preview_->run_next_pass();
      frame_gl_work_ = true;
      gl_ms += ms_between(start, Clock::now());
    }
  }

  void trace() {
    const auto start = Clock::now();
    auto used_ms = [&] { return ms_between(start, Clock::now()); };
    if (preview_->samples() < last_samples_) history_.clear();  // the accumulation was reset
    bool fresh = true;  // nothing waited for or run yet in this display frame
    for (;;) {
      if (tracing_) {
        const auto wait = std::chrono::duration<double, std::milli>(std::max(0.0, kTraceBudgetMs - used_ms()));
        if (trace_result_.wait_for(wait) != std::future_status::ready) break;
        stop_tracing(/*cancel=*/false);
        fresh = false;
        frame_gl_work_ = true;
      }
      run_passes(used_ms(), fresh);
      fresh = false;
      if (preview_->passes_pending()) break;
      if (frame_stats_pending_) average_stage_times(preview_->last_times()), frame_stats_pending_ = false;
      if (camera_changed_ || settings_changed_) break;
      if (advance_path()) break;
      if (preview_->samples() == 0) accumulation_start_ = Clock::now();  // --time counts from here
      if (paused_ || spp_reached()) {
        if (!finished_ && spp_reached()) preview_->finish(), finished_ = true;
        break;
      }
      finished_ = false;
      start_trace();
      if (used_ms() >= kTraceBudgetMs) break;
    }
    if (frames_since_display_ > 0) {
      if (stage_ms_.path_tracing > 0)
        paths_per_second_ = 0.8 * paths_per_second_ + 0.2 * (double(width_) * height_ / (stage_ms_.path_tracing / 1000.0));
      const auto& counts = preview_->case_counts();
      history_.push_back(float(counts[kCaseNoFiltered] + counts[kCaseUnfiltered]) / (width_ * height_));
      if (history_.size() > kPlotLength) history_.pop_front();
      frames_since_display_ = 0;
    }
    last_samples_ = preview_->samples();
  }

  // --camera-path: once the path frame holds its samples, the next path frame's camera (applied by
  // apply_changes, as a move of the mouse is); the last frame then stays and accumulates.
  bool advance_path() {
    if (!playing_path_ || preview_->samples() < options_.spp_per_frame) return false;
    if (path_frame_ + 1 >= path_.frame_count()) {
      playing_path_ = false;
      return false;
    }
    ++path_frame_;
    camera_changed_ = true;
    return true;
  }

  void average_stage_times(const StageTimes& t) {
    const double a = 0.2;
    stage_ms_.path_tracing = (1 - a) * stage_ms_.path_tracing + a * t.path_tracing;
    stage_ms_.upload = (1 - a) * stage_ms_.upload + a * t.upload;
    if (t.range > 0) stage_ms_.range = t.range;
    stage_ms_.blend = (1 - a) * stage_ms_.blend + a * t.blend;
    stage_ms_.tonemap = (1 - a) * stage_ms_.tonemap + a * t.tonemap;
  }

  void render_views() {
    if (++auto_scale_counter_ % 8 == 1) {
      views_->update_auto_scale(split_ ? split_left_ : view_, *preview_);
      if (split_) views_->update_auto_scale(split_right_, *preview_);
    }
    if (split_) views_->show_split(split_left_, split_right_, divider_, *preview_);
    else views_->show(view_, *preview_);
  }

  void draw_to_window() {
    int w, h;
    glfwGetFramebufferSize(window_, &w, &h);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glViewport(0, 0, w, h);
    glClearColor(0.08f, 0.08f, 0.09f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    window_width_ = w, window_height_ = h;
  }

  // --- capture ----------------------------------------------------------------------------------
  void capture() {
    try {
      options_.scene.width = width_, options_.scene.height = height_;
      stop_tracing(/*cancel=*/false);  // the frame in flight and its passes first
      while (preview_->passes_pending()) preview_->run_next_pass();
      preview_->finish();  // like an interrupted `pxf render`: the last-frame filter run, blend, tone map
      RenderReport report;
      report.scene = &options_.scene;
      report.gl_backend = context_.backend_name();
      report.gl_renderer = context_.gl_renderer();
      report.wall_ms = ms_between(started_, Clock::now());
      write_render_outputs(out_dir_, *preview_, report);
      views_->show(view_, *preview_);
      const std::string view_png = out_dir_ + "/view-" + buffer_view_names()[static_cast<int>(view_)] + ".png";
      write_png(view_png, views_->shown(false).download({"R", "G", "B"}));
      status_message_ = "saved " + view_png + ", final.png, final.exr, buffers.exr, stats.json in " + out_dir_;
    } catch (const Error& e) {
      status_message_ = std::string("capture failed: ") + e.what();
    }
    std::fprintf(stderr, "pxf explore: %s\n", status_message_.c_str());
  }

  void finish_run() {
    if (options_.capture_on_exit) capture();
    if (!options_.screenshot.empty()) {
      write_png(options_.screenshot, read_window(window_width_, window_height_));
      std::string cases;
      for (uint32_t n : shown_case_counts_) cases += " " + std::to_string(n);
      std::fprintf(stderr, "pxf explore: wrote %s (its status line counts the blend cases%s; longest display frame %.0f ms)\n",
                   options_.screenshot.c_str(), cases.c_str(), longest_frame_ms_);
    }
  }

  ExploreOptions& options_;
  GlContext& context_;
  GLFWwindow* window_;
  PreviewSettings settings_;
  std::unique_ptr<Scene> scene_;
  std::unique_ptr<Preview> preview_;
  std::unique_ptr<CameraController> controller_;
  std::unique_ptr<ViewRenderer> views_;
  std::array<uint32_t, kBlendCaseCount> shown_case_counts_{};  // the status line's, last built
  int width_ = 0, height_ = 0, window_width_ = 0, window_height_ = 0;
  float scale_ = 1.0f;
  BufferView view_ = BufferView::Final, split_left_ = BufferView::Final, split_right_ = BufferView::Unfiltered;
  bool split_ = false, inspector_ = true, paused_ = false, finished_ = false;
  float divider_ = 0.0f;
  bool dragging_divider_ = false, dragging_camera_ = false, flying_ = false;
  bool camera_changed_ = false, settings_changed_ = false, applied_moving_ = false, fast_while_moving_ = false;
  StageTimes stage_ms_;
  double paths_per_second_ = 0;
  std::deque<float> history_;
  int last_samples_ = 0, auto_scale_counter_ = 0, frames_since_display_ = 0;
  bool tracing_ = false;               // a worker is running Preview::trace_frame
  bool frame_stats_pending_ = false;
  std::future<bool> trace_result_;
  std::vector<uint32_t> samples_snapshot_;  // per-pixel n for the inspector (the worker writes n)
  CameraPath path_;                  // --camera-path
  int path_frame_ = 0;
  bool playing_path_ = false;
  long frames_traced_ = 0;             // in all, camera moves included
  double longest_frame_ms_ = 0;        // longest display frame (the UI budget, kUiBudgetMs)
  Clock::time_point frame_start_{};    // of the display frame being built
  double camera_change_ms_ = 0;        // the last camera change's GL work (apply_changes)
  bool frame_gl_work_ = false;         // this display frame waited for a traced frame or ran a pass
  // The views' and the window's drawing, after the GL steps, as the budget predicts it: the longest
  // of the last 8 display frames: the drawing varies severalfold from frame to frame on a
  // software rasterizer, and predicting from the last one alone let display frames run long.
  std::array<double, 8> recent_ui_draw_ms_{};
  double ui_draw_ms_ = 0;
  std::string out_dir_, scene_path_, scene_error_, status_message_;
  Clock::time_point started_;
  Clock::time_point accumulation_start_ = Clock::now();
};

// The window fits the image at 1:1 (at least) beside the panel, within a usual screen.
GlContextOptions window_options(const ExploreOptions& o, int width, int height) {
  GlContextOptions w;
  w.want_window = true;
  w.title = "pxf explore";
  const int zoom = std::max(o.zoom, 1);
  w.width = std::clamp(width * zoom, 480, 1600) + static_cast<int>(kPanelWidth);
  w.height = std::clamp(height * zoom, 760, 1000);
  w.vsync = o.frames == 0;  // tests run as fast as they can
  return w;
}

}  // namespace

int run_explorer(ExploreOptions& options) {
  // The window size depends on the image size: known from --size, else a common default.
  const int width = options.scene.width > 0 ? options.scene.width : 512;
  const int height = options.scene.height > 0 ? options.scene.height : 512;
  set_gl_timing(options.scene.stage_timing);
  auto context = create_gl_context(parse_gl_backend(options.scene.gl), window_options(options, width, height));
  if (!context->native_window())
    throw Error(std::string("explore needs a window; the '") + context->backend_name() +
                "' back end has none (is DISPLAY set? try --gl window)");
  Explorer explorer(options, *context);
  return explorer.run();
}

}  // namespace pxf
