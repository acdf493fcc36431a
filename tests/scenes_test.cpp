// No NaN or Inf in any output buffer for any built-in scene, through the same core
// as `pxf render`, with every filter variant the command line offers.
#include <gtest/gtest.h>

#include "pathtracer/pathtracer.h"
#include "scene/load.h"
#include "tests/test_support.h"

using namespace pxf;

TEST(Scenes, EveryBuiltinSceneRendersWithoutNonFiniteValues) {
  const auto scenes = builtin_scenes();
  ASSERT_GE(scenes.size(), 4u);
  for (const BuiltinScene& s : scenes) {
    for (size_t kind = 0; kind < filter_option_names().size(); ++kind) {
      const std::string& filter = filter_option_names()[kind];
      PreviewSettings settings;
      settings.filter.kind = static_cast<FilterKind>(kind);
      auto preview = test_support::render_preview(s.name, 48, 32, 3, settings);
      for (const Layer& layer : preview->buffers()) {
        EXPECT_EQ(count_nonfinite(layer.image), 0u) << s.name << " " << filter << " " << layer.name;
      }
      const Image display = preview->display_image();
      EXPECT_EQ(count_nonfinite(display), 0u) << s.name;
      double sum = 0;
      for (float v : display.pixels) sum += v;
      EXPECT_GT(sum, 0.0) << s.name << ": black image";
    }
  }
}
