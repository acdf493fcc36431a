// Tests of `pxf explore` (issue 6): the camera controls and view names as units, and the whole
// explorer in a window under Xvfb against a headless `pxf render` of the same settings.
#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "app/explorer_camera.h"
#include "app/explorer_views.h"
#include "image/image.h"

namespace pxf {
namespace {

Camera test_camera() {
  Camera c;
  c.camera_to_world[3] = glm::vec4(0.0f, 1.0f, 5.0f, 1.0f);  // looking down -Z at the origin
  return c;
}
const Bounds kUnitBox{glm::vec3(-1.0f), glm::vec3(1.0f)};

void expect_near(const glm::vec3& a, const glm::vec3& b, float tol = 1e-4f) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

TEST(ExplorerCamera, StartsAndResetsAtTheSceneCameraExactly) {
  CameraController control(test_camera(), kUnitBox);
  EXPECT_EQ(control.camera().camera_to_world, test_camera().camera_to_world);
  expect_near(control.target(), glm::vec3(0.0f, 1.0f, 0.0f));  // on the view axis, as deep as the center
  control.orbit(40, 10);
  control.pan(5, 5, 100);
  control.zoom(2);
  EXPECT_NE(control.camera().camera_to_world, test_camera().camera_to_world);
  control.reset();
  EXPECT_EQ(control.camera().camera_to_world, test_camera().camera_to_world);
}

TEST(ExplorerCamera, OrbitKeepsTheDistanceAndLooksAtTheTarget) {
  CameraController control(test_camera(), kUnitBox);
  const float distance = glm::length(control.eye() - control.target());
  control.orbit(120, -60);
  EXPECT_NEAR(glm::length(control.eye() - control.target()), distance, 1e-4f);
  const glm::vec3 forward = -glm::vec3(control.camera().camera_to_world[2]);
  expect_near(glm::normalize(forward), glm::normalize(control.target() - control.eye()));
  expect_near(glm::vec3(control.camera().camera_to_world[3]), control.eye());
  control.orbit(0, 10000);  // pitch is clamped short of the pole: the frame stays orthonormal
  EXPECT_NEAR(glm::length(glm::vec3(control.camera().camera_to_world[0])), 1.0f, 1e-4f);
}

TEST(ExplorerCamera, PanMovesEyeAndTargetTogetherZoomAndFlyMoveAlongTheView) {
  CameraController control(test_camera(), kUnitBox);
  control.pan(-10, 0, 100);  // drag left: the camera moves right (+X)
  expect_near(control.eye() - control.target(), glm::vec3(0.0f, 0.0f, 5.0f));
  EXPECT_GT(control.eye().x, 0.0f);
  control.zoom(1);
  EXPECT_LT(glm::length(control.eye() - control.target()), 5.0f);
  const glm::vec3 before = control.eye();
  control.fly(glm::vec3(0, 0, 1), 1.0f);  // forward = -Z here
  EXPECT_LT(control.eye().z, before.z);
  EXPECT_NEAR(control.eye().x, before.x, 1e-4f);
}

// An orthographic camera: zoom narrows the view (moving would change nothing on screen), pan
// moves by the view height (2 ymag) per image height, reset restores ymag.
TEST(ExplorerCamera, OrthographicZoomNarrowsTheViewAndPanFollowsTheCursor) {
  Camera home = test_camera();
  home.orthographic = true;
  home.ymag = 2.0f;
  CameraController control(home, kUnitBox);
  const glm::vec3 eye = control.eye();
  control.zoom(1);
  EXPECT_NEAR(control.camera().ymag, 2.0f * 0.85f, 1e-6f);
  expect_near(control.eye(), eye);
  control.pan(-50, 0, 100);  // half the image height to the left: the camera moves ymag to the right
  EXPECT_NEAR(control.eye().x - eye.x, 0.5f * 2.0f * control.camera().ymag, 1e-4f);
  EXPECT_TRUE(control.camera().orthographic);
  control.reset();
  EXPECT_FLOAT_EQ(control.camera().ymag, 2.0f);
}

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

}  // namespace
}  // namespace pxf
