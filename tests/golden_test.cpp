// Golden images: small, fixed seed and spp, headless on OSMesa. Each case names the
// buffers it checks and a per-pixel tolerance plus a maximum fraction of failing pixels. A failing
// case writes the image, the golden and a difference image under build/test-failures/<case>/.
// Regenerate every golden (after an intended change, and look at them):
//   PXF_UPDATE_GOLDENS=1 build/tests/integration_tests --gtest_filter='*Golden*'
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>

#include "app/render_output.h"
#include "tests/test_support.h"

using namespace pxf;

namespace {

struct GoldenCase {
  std::string name, scene;
  int width, height, spp;
  FilterKind filter;
  float threshold;
  std::vector<std::string> layers;
  float abs_tolerance, rel_tolerance;  // a pixel fails when |got - golden| > abs + rel * |golden|
  double max_failing_fraction;
};

const std::vector<GoldenCase> kCases = {
    {"cornell_128_filtered", "cornell", 128, 128, 16, FilterKind::BilateralDepth, 0.001f, {"final", "blend"}, 2e-3f, 0.02f, 0.01},
    {"cornell_128_bilateral", "cornell", 128, 128, 8, FilterKind::Bilateral, 0.01f, {"final", "blend"}, 2e-3f, 0.02f, 0.01},
};

std::string golden_path(const GoldenCase& c) { return std::string(PXF_SOURCE_DIR) + "/tests/golden/" + c.name + ".exr"; }

Image difference(const Image& a, const Image& b) {
  Image d = a;
  for (size_t i = 0; i < d.pixels.size(); ++i) d.pixels[i] = std::abs(a.pixels[i] - b.pixels[i]);
  return d;
}

double failing_fraction(const Image& got, const Image& golden, float abs_tol, float rel_tol) {
  size_t failing = 0;
  const size_t n = got.channels.size();
  for (size_t p = 0; p < got.pixel_count(); ++p)
    for (size_t c = 0; c < n; ++c) {
      const float g = got.pixels[p * n + c], r = golden.pixels[p * n + c];
      if (!(std::abs(g - r) <= abs_tol + rel_tol * std::abs(r))) {
        ++failing;
        break;
      }
    }
  return static_cast<double>(failing) / got.pixel_count();
}

class Golden : public ::testing::TestWithParam<GoldenCase> {};

TEST_P(Golden, MatchesWithinTolerance) {
  const GoldenCase& c = GetParam();
  PreviewSettings settings;
  settings.filter.kind = c.filter;
  settings.threshold = c.threshold;
  auto preview = test_support::render_preview(c.scene, c.width, c.height, c.spp, settings);
  const std::vector<Layer> buffers = preview->buffers();
  std::vector<Layer> got;
  for (const auto& name : c.layers) got.push_back({name, layer_image(buffers, name)});

  if (std::getenv("PXF_UPDATE_GOLDENS")) {
    write_exr(golden_path(c), got);
    GTEST_SKIP() << "rewrote " << golden_path(c);
  }
  const std::vector<Layer> golden = read_exr_layers(golden_path(c));
  for (const Layer& layer : got) {
    const Image expected = read_exr(golden_path(c), layer.name);
    ASSERT_EQ(expected.width, layer.image.width);
    const double fraction = failing_fraction(layer.image, expected, c.abs_tolerance, c.rel_tolerance);
    EXPECT_LE(fraction, c.max_failing_fraction) << c.name << "/" << layer.name;
    if (fraction > c.max_failing_fraction) {
      const std::string dir = test_support::failure_dir(c.name);
      write_exr(dir + "/" + layer.name + "_image.exr", layer.image);
      write_exr(dir + "/" + layer.name + "_golden.exr", expected);
      write_exr(dir + "/" + layer.name + "_difference.exr", difference(layer.image, expected));
      ADD_FAILURE() << "wrote image, golden and difference to " << dir;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Cornell, Golden, ::testing::ValuesIn(kCases),
                         [](const auto& info) { return info.param.name; });

// The comparison itself must be able to fail: a golden compared with a perturbed copy.
TEST(GoldenTolerance, DetectsAChangedImage) {
  Image a = Image::rgb(10, 10, 0.5f), b = a;
  EXPECT_EQ(failing_fraction(a, b, 1e-3f, 0.02f), 0.0);
  for (int x = 0; x < 10; ++x) b.at(x, 0, 1) = 0.6f;  // one row off by 20 %
  EXPECT_NEAR(failing_fraction(b, a, 1e-3f, 0.02f), 0.1, 1e-12);
}

}  // namespace
