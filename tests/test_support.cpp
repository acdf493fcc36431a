#include "tests/test_support.h"

#include <filesystem>

#include "pathtracer/pathtracer.h"

namespace pxf::test_support {

GlContext& headless_context() {
  static std::unique_ptr<GlContext> context = create_gl_context(GlBackend::OSMesa);
  context->make_current();
  return *context;
}

std::unique_ptr<Preview> render_preview(const std::string& scene_name, int width, int height, int spp,
                                        const PreviewSettings& settings) {
  headless_context();
  const Scene scene = load_scene(scene_name);
  PreviewSettings s = settings;
  s.trace.all_hv = s.trace.all_hv || scene.defaults.all_hv;
  auto preview = std::make_unique<Preview>(scene, s, width, height);
  for (int i = 0; i < spp; ++i) preview->add_frame(i + 1 == spp, false);
  return preview;
}

std::string failure_dir(const std::string& test_name) {
  const std::string dir = std::string(PXF_BINARY_DIR) + "/test-failures/" + test_name;
  std::filesystem::create_directories(dir);
  return dir;
}

}  // namespace pxf::test_support
