// Tests of `pxf explore`: the view names as units, and the whole
// explorer in a window under Xvfb against a headless `pxf render` of the same settings.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>

#include "app/explorer/explorer_views.h"
#include "gl/context.h"
#include "image/image.h"
#include "pathtracer/pathtracer.h"
#include "preview/adaptive.h"
#include "preview/pixel_probe.h"
#include "preview/preview.h"
#include "scene/load.h"

namespace pxf {
namespace {

TEST(ExplorerViews, NamesDigitsAndScalarViews) {
  EXPECT_EQ(buffer_view_names().size(), static_cast<size_t>(kBufferViewCount));
  for (const std::string& name : buffer_view_names())
    EXPECT_EQ(buffer_view_names()[static_cast<int>(parse_buffer_view(name))], name);
  EXPECT_THROW(parse_buffer_view("nope"), Error);
  EXPECT_EQ(BufferView(buffer_view_of_digit(1)), BufferView::Final);
  EXPECT_EQ(BufferView(buffer_view_of_digit(0)), BufferView::Case);
  EXPECT_EQ(buffer_view_of_digit(10), -1);
  EXPECT_TRUE(is_scalar_view(BufferView::VarU));
  EXPECT_FALSE(is_scalar_view(BufferView::Final));
  // The adaptive-sampling views: reachable by name (--view, --split, the UI's list), no number key.
  EXPECT_EQ(parse_buffer_view("samples"), BufferView::Samples);
  EXPECT_EQ(parse_buffer_view("active"), BufferView::Active);
  for (int digit = 0; digit <= 9; ++digit) {
    EXPECT_NE(BufferView(buffer_view_of_digit(digit)), BufferView::Samples);
    EXPECT_NE(BufferView(buffer_view_of_digit(digit)), BufferView::Active);
  }
  EXPECT_TRUE(is_scalar_view(BufferView::Samples));  // false color with a legend
  EXPECT_FALSE(is_scalar_view(BufferView::Active));  // two colors with the shares
}

// --- the samples and active views and the status line, headless --------------------------------

// The status line from known counts: every figure and its format, and the empty mask (adaptive off
// or warm-up) counted as every pixel active.
TEST(ExplorerSampling, StatusLineNamesCleanShareCountsAndActiveShare) {
  SamplingSnapshot s;
  s.paths = {10, 20, 30, 41};
  s.active = {1, 0, 0, 0};
  EXPECT_EQ(sampling_status_line(0.375, s), "clean (case 2): 37.5 %   paths/pixel mean 25.2 (min 10, max 41)   active 25.0 %");
  s.active.clear();
  EXPECT_EQ(sampling_status_line(1.0, s), "clean (case 2): 100.0 %   paths/pixel mean 25.2 (min 10, max 41)   active 100.0 %");
  EXPECT_DOUBLE_EQ(active_share({}), 1.0);
  EXPECT_DOUBLE_EQ(active_share({0, 0, 1, 1, 1}), 0.6);
}

// The turbo polynomial of shaders/view_colormap.glsl, on the CPU (an independent copy: the test
// fails if the shader's mapping or the view's scale changes).
glm::vec3 turbo(float x) {
  const glm::vec4 r4(0.13572138f, 4.61539260f, -42.66032258f, 132.13108234f);
  const glm::vec4 g4(0.09140261f, 2.19418839f, 4.84296658f, -14.18503333f);
  const glm::vec4 b4(0.10667330f, 12.64194608f, -60.58204836f, 110.36276771f);
  const glm::vec2 r2(-152.94239396f, 59.28637943f), g2(4.27729857f, 2.82956604f), b2(-89.90310912f, 27.34824973f);
  x = std::clamp(x, 0.0f, 1.0f);
  const glm::vec4 v4(1.0f, x, x * x, x * x * x);
  const glm::vec2 v2 = glm::vec2(v4.z, v4.w) * v4.z;
  return glm::clamp(glm::vec3(glm::dot(v4, r4) + glm::dot(v2, r2), glm::dot(v4, g4) + glm::dot(v2, g2),
                              glm::dot(v4, b4) + glm::dot(v2, b2)),
                    0.0f, 1.0f);
}

GlContext& headless_context() {
  static std::unique_ptr<GlContext> context = create_gl_context(GlBackend::OSMesa);
  context->make_current();
  return *context;
}

// Cornell at 32x24, adaptive, 40 frames (16 uniform warm-up frames, then the allocation): uneven
// counts and a next mask that traces some pixels and skips others. The scene outlives the preview.
class ExplorerSamplingViews : public ::testing::Test {
 protected:
  static constexpr int kW = 32, kH = 24;
  void SetUp() override {
    headless_context();
    static const Scene scene = load_scene("cornell");
    PreviewSettings settings;
    settings.adaptive = true;
    settings.threshold = 0.05f;  // loose: many pixels clean early, so the allocation differs per pixel
    preview_ = std::make_unique<Preview>(scene, settings, kW, kH);
    for (int i = 0; i < 40; ++i) preview_->add_frame(i + 1 == 40);
    views_ = std::make_unique<ViewRenderer>(kW, kH);
    views_->set_sampling(SamplingSnapshot::of(*preview_));
  }
  // The view as RGB in [0,1], top row first.
  Image shown(BufferView view) { return views_->render(view, *preview_, 0).download({"R", "G", "B"}); }
  std::unique_ptr<Preview> preview_;
  std::unique_ptr<ViewRenderer> views_;
};

TEST_F(ExplorerSamplingViews, SamplesViewIsTheCountsOnTheLegendsLinearScale) {
  const std::vector<uint32_t>& paths = preview_->pixel_samples();
  ASSERT_EQ(paths.size(), static_cast<size_t>(kW * kH));
  const SampleCounts counts = sample_counts(paths);
  ASSERT_LT(counts.min, counts.max) << "the allocation traced every pixel alike: nothing uneven to show";
  EXPECT_NEAR(counts.mean, 40.0, 1.0);  // an adaptive frame traces a uniform one's paths, spread unevenly
  EXPECT_GT(counts.max, 40u);
  const ScalarScale& s = views_->scale(BufferView::Samples);  // set by set_sampling, no update call
  EXPECT_FALSE(s.log);
  EXPECT_EQ(s.lo, float(counts.min));  // the whole range of the image
  EXPECT_EQ(s.hi, float(counts.max));
  const Image image = shown(BufferView::Samples);
  double worst = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const float n = float(paths[static_cast<size_t>(y) * kW + x]);  // row-major, top row first
      const glm::vec3 want = turbo((n - s.lo) / (s.hi - s.lo));
      for (int c = 0; c < 3; ++c) worst = std::max(worst, double(std::abs(image.at(x, y, c) - want[c])));
    }
  EXPECT_LE(worst, 1.5 / 255) << "samples view differs from the CPU mapping";
  // Equal counts (a uniform render) sit mid-scale, one path wide.
  SamplingSnapshot uniform{std::vector<uint32_t>(kW * kH, 7), {}};
  views_->set_sampling(uniform);
  EXPECT_EQ(views_->scale(BufferView::Samples).lo, 6.5f);
  EXPECT_EQ(views_->scale(BufferView::Samples).hi, 7.5f);
  const Image flat = shown(BufferView::Samples);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(flat.at(kW - 1, kH - 1, c), turbo(0.5f)[c], 1.5 / 255);
}

TEST_F(ExplorerSamplingViews, ActiveViewShowsTheNextMaskAndAnEmptyMaskAsEveryPixel) {
  const std::vector<uint8_t>& mask = preview_->next_active();
  ASSERT_EQ(mask.size(), static_cast<size_t>(kW * kH));
  const double share = active_share(mask);
  ASSERT_GT(share, 0.0);
  ASSERT_LT(share, 1.0) << "the next frame traces every pixel: nothing skipped to show";
  auto expect_colors = [&](const Image& image, const std::vector<uint8_t>& active) {
    int wrong = 0;
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x) {
        const size_t p = static_cast<size_t>(y) * kW + x;
        const CaseStyle& style = active_styles()[active.empty() || active[p] > 0 ? 1 : 0];
        const float want[3] = {style.r, style.g, style.b};
        for (int c = 0; c < 3; ++c) wrong += std::abs(image.at(x, y, c) - want[c]) > 0.6f / 255;
      }
    return wrong;
  };
  EXPECT_EQ(expect_colors(shown(BufferView::Active), mask), 0);
  views_->set_sampling(SamplingSnapshot{preview_->pixel_samples(), {}});  // adaptive off, or warm-up
  EXPECT_EQ(expect_colors(shown(BufferView::Active), {}), 0);
}

// The status line of this preview: its figures are the preview's own.
TEST_F(ExplorerSamplingViews, StatusLineOfAnAdaptivePreview) {
  const SampleCounts counts = sample_counts(preview_->pixel_samples());
  const std::vector<uint8_t>& mask = preview_->next_active();
  const double active = 100.0 * (mask.size() - std::count(mask.begin(), mask.end(), 0)) / mask.size();
  char want[200];
  std::snprintf(want, sizeof want, "clean (case 2): %.1f %%   paths/pixel mean %.1f (min %u, max %u)   active %.1f %%",
                100.0 * preview_->case_counts()[kCaseUnfiltered] / (kW * kH), counts.mean, counts.min, counts.max, active);
  EXPECT_EQ(sampling_status_line(preview_->case2_share(), views_->sampling()), want);
}

// --- the inspector shows the blend's own decision, headless -------------------------------------

// Cornell at 32x24, 6 frames with the default settings (variance pooling, the centre weight, the
// bias guard): at every pixel the inspector's case is the blend pass's and its s the pass's to the
// rounding of the C++ compilation (it sums in double; at one pixel here every known neighbour lies
// across a range edge, where it pooled what the shader did not before kMinPooledWeight). Somewhere
// the pooled variance, not the pixel's own, decided s (the old inspector's u), so an inspector
// that used the own variance again would fail here.
TEST(ExplorerInspector, ShowsTheBlendPassDecisionAtEveryPixel) {
  headless_context();
  static const Scene scene = load_scene("cornell");
  constexpr int kW = 32, kH = 24, kFrames = 6;
  Preview preview(scene, PreviewSettings{}, kW, kH);
  for (int i = 0; i < kFrames; ++i) preview.add_frame(i + 1 == kFrames);
  const Image s = preview.blend().s_image(), cases = preview.blend().case_image();
  int compared = 0, decided_by_pooling = 0, surfaces = 0, delta_surfaces = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      SCOPED_TRACE(testing::Message() << "pixel " << x << "," << y);
      const PixelProbe probe = probe_pixel(preview, preview.pixel_samples(), x, y);
      ASSERT_TRUE(probe.blended);
      ASSERT_TRUE(probe.blend.switches.has_filtered && probe.blend.switches.has_guide);
      const shared::BlendPixel& shown = probe.blend.decision;
      EXPECT_EQ(shown.blend_case, static_cast<int>(cases.at(x, y, 0)));
      EXPECT_NEAR(shown.s, s.at(x, y, 0), 1e-4f);
      EXPECT_EQ(probe.final_s.a, s.at(x, y, 0));
      // The material under the pixel (the box, or beside it at this aspect the background) and its lobes.
      surfaces += probe.surface.hit;
      for (const SurfaceLobe& lobe : probe.surface.lobes) delta_surfaces += lobe.delta && lobe.probability == 1.0f;
      if (!shared::blend_compares_variances(probe.blend.texels, probe.blend.switches)) continue;
      ++compared;
      shared::BlendVarianceInputs own = probe.blend.variance_inputs;
      own.var_u_pooled = shared::clean_var(probe.blend.texels.hv.a);
      const float s_own = shared::blend_pixel(probe.blend.texels, probe.blend.switches, own).s;
      decided_by_pooling += std::abs(s_own - s.at(x, y, 0)) > 0.01f;
    }
  EXPECT_GT(compared, kW * kH / 4) << "too few pixels whose variances the blend compared";
  EXPECT_GT(surfaces, kW * kH / 2);
  EXPECT_GT(delta_surfaces, 10) << "the mirror and glass spheres' pixels show a delta lobe";
  EXPECT_GT(decided_by_pooling, 0) << "no pixel whose s the pooled variance changed: the test cannot tell an "
                                      "inspector that uses the pixel's own variance";
}

// --- the explorer in a window ----------------------------------------------------------------

const std::string kPxf = PXF_BINARY_DIR "/app/pxf";
constexpr int kSize = 128;

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Runs the explorer until its 8 spp are done (then a capture and a window screenshot, in the
// display frame that finished them: --frames 1) and a headless
// render of the same settings, once for all the window tests.
class ExplorerWindow : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (std::system("command -v xvfb-run > /dev/null 2>&1") != 0) return;
    // One folder per process: ctest runs each test case in its own process, possibly at once.
    dir_ = std::filesystem::path(PXF_BINARY_DIR) / "app" / ("explorer_test_out-" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
    const std::string d = dir_.string();
    const std::string common = " --scene cornell --size 128x128 --seed 3 --threshold 0.002";
    const std::string explore = "xvfb-run -a -s '-screen 0 1600x1000x24' " + kPxf + " explore --frames 1 --spp 8 --zoom 1" +
                                common + " --screenshot " + d + "/window.png --capture --out " + d + "/explore > " + d +
                                "/explore.log 2>&1";
    const std::string render =
        kPxf + " render --gl osmesa --spp 8 --quiet" + common + " --out " + d + "/render > " + d + "/render.log 2>&1";
    explore_status_ = std::system(explore.c_str());
    render_status_ = std::system(render.c_str());
  }
  void SetUp() override {
    if (dir_.empty()) GTEST_SKIP() << "xvfb-run is not installed";
    ASSERT_EQ(explore_status_, 0) << read_text((dir_ / "explore.log").string());
    ASSERT_EQ(render_status_, 0) << read_text((dir_ / "render.log").string());
  }
  static std::filesystem::path dir_;
  static int explore_status_, render_status_;
};
std::filesystem::path ExplorerWindow::dir_;
int ExplorerWindow::explore_status_ = -1, ExplorerWindow::render_status_ = -1;

TEST_F(ExplorerWindow, ScreenshotShowsTheUiAndTheRenderedImage) {
  const Image window = read_ldr_or_hdr((dir_ / "window.png").string());
  const Image rendered = read_ldr_or_hdr((dir_ / "render" / "final.png").string());
  ASSERT_GE(window.width, kSize + 400);
  ASSERT_GE(window.height, kSize);
  // The image sits at 1:1 in the top-left corner (--zoom 1): it matches the headless render.
  double diff = 0, image_mean = 0;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x)
      for (int c = 0; c < 3; ++c) {
        diff += std::abs(window.at(x, y, c) - rendered.at(x, y, c));
        image_mean += window.at(x, y, c);
      }
  const double n = 3.0 * kSize * kSize;
  EXPECT_LT(diff / n, 1.5 / 255) << "explorer image differs from pxf render's final.png";
  EXPECT_GT(image_mean / n, 0.05) << "image region is blank";
  // The panel (right part) holds text: many distinct bright and dark pixels.
  int bright = 0, dark = 0;
  for (int y = 0; y < window.height; ++y)
    for (int x = window.width - 400; x < window.width; ++x) {
      const float v = window.at(x, y, 0) + window.at(x, y, 1) + window.at(x, y, 2);
      bright += v > 2.0f;
      dark += v < 0.5f;
    }
  EXPECT_GT(bright, 2000) << "no UI text in the panel";
  EXPECT_GT(dark, 2000);
}

// The status line counts the blend cases of the frame it is drawn with: the explorer prints the
// counts its last status line showed, and they are the captured case layer's (the same blend).
// (The panel was once built before the frame's tracing and passes, one blend behind its views.)
TEST_F(ExplorerWindow, StatusLineCountsTheCasesOfTheShownBlend) {
  const std::string log = read_text((dir_ / "explore.log").string());
  const std::string key = "its status line counts the blend cases";
  const size_t at = log.find(key);
  ASSERT_NE(at, std::string::npos) << log;
  std::istringstream line(log.substr(at + key.size()));
  std::array<uint64_t, kBlendCaseCount> shown{};
  for (uint64_t& n : shown) ASSERT_TRUE(line >> n) << log;
  const std::vector<Layer> layers = read_exr_layers((dir_ / "explore" / "buffers.exr").string());
  std::array<uint64_t, kBlendCaseCount> captured{};
  for (float code : layer_image(layers, "case").pixels) {
    ASSERT_GE(code, 0.0f);
    ASSERT_LT(code, float(kBlendCaseCount));
    ++captured[static_cast<int>(code)];
  }
  EXPECT_EQ(shown, captured);
  EXPECT_EQ(captured[kCaseNoFiltered], 0u);  // the filter has run: the test compares a real blend
}

TEST_F(ExplorerWindow, CapturedBuffersEqualPxfRender) {
  const std::vector<Layer> explored = read_exr_layers((dir_ / "explore" / "buffers.exr").string());
  const std::vector<Layer> rendered = read_exr_layers((dir_ / "render" / "buffers.exr").string());
  ASSERT_EQ(explored.size(), rendered.size());
  for (size_t i = 0; i < explored.size(); ++i) {
    const Image& a = explored[i].image;
    const Image& b = rendered[i].image;
    EXPECT_EQ(explored[i].name, rendered[i].name);
    ASSERT_EQ(a.pixels.size(), b.pixels.size()) << explored[i].name;
    double max_rel = 0;
    for (size_t k = 0; k < a.pixels.size(); ++k)
      max_rel = std::max(max_rel, std::abs(double(a.pixels[k]) - b.pixels[k]) / (1e-3 + std::abs(double(b.pixels[k]))));
    EXPECT_LT(max_rel, 1e-4) << "layer " << explored[i].name;
  }
  EXPECT_TRUE(std::filesystem::exists(dir_ / "explore" / "final.png"));
  EXPECT_TRUE(std::filesystem::exists(dir_ / "explore" / "stats.json"));
  EXPECT_TRUE(std::filesystem::exists(dir_ / "explore" / "view-final.png"));
}

// The history view: a kept pixel is green, brighter with more weight; disoccluded red,
// outside blue, no history grey.
TEST(ExplorerViews, HistoryViewColorsShowOutcomeAndWeight) {
  Image outcome = Image::gray(5, 1), weight = Image::gray(5, 1);
  const int codes[5] = {shared::kHistoryNone, shared::kHistoryKept, shared::kHistoryKept, shared::kHistoryDisoccluded,
                          shared::kHistoryOutside};
  for (int i = 0; i < 5; ++i) outcome.pixels[i] = static_cast<float>(codes[i]);
  weight.pixels[1] = 0.1f;
  weight.pixels[2] = 0.9f;
  const Image c = history_view_colors(outcome, weight);
  EXPECT_FLOAT_EQ(c.at(0, 0, 0), c.at(0, 0, 1));  // grey
  EXPECT_GT(c.at(1, 0, 1), c.at(1, 0, 0));        // green
  EXPECT_GT(c.at(2, 0, 1), c.at(1, 0, 1));        // more weight, brighter
  EXPECT_GT(c.at(3, 0, 0), c.at(3, 0, 1));        // red
  EXPECT_GT(c.at(4, 0, 2), c.at(4, 0, 0));        // blue
}

}  // namespace
}  // namespace pxf
