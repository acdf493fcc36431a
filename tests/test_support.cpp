#include "tests/test_support.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>

#include "pathtracer/pathtracer.h"
#include "scene/load.h"

namespace pxf::test_support {

GlContext& headless_context() {
  static std::unique_ptr<GlContext> context = create_gl_context(GlBackend::OSMesa);
  context->make_current();
  return *context;
}

std::unique_ptr<Preview> render_preview(const std::string& scene_name, int width, int height, int spp,
                                        const PreviewSettings& settings) {
  headless_context();
  // The Preview references its scene: each scene is loaded once and kept for the test binary's life.
  static std::map<std::string, std::unique_ptr<const Scene>> scenes;
  std::unique_ptr<const Scene>& cached = scenes[scene_name];
  if (!cached) cached = std::make_unique<const Scene>(load_scene(scene_name));
  const Scene& scene = *cached;
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

std::string temp_dir(const std::string& suite, const std::string& name) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() /
                                    ("pxf_" + suite + "_test_" + std::to_string(::getpid())) / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir.parent_path());
  return dir.string();
}

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

PxfResult run_pxf(const std::string& args, const std::string& suite) {
  const std::string base = temp_dir(suite, "io");
  std::filesystem::create_directories(base);
  const std::string cmd = std::string(PXF_EXECUTABLE) + " " + args + " >" + base + "/out 2>" + base + "/err";
  const int status = std::system(cmd.c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(base + "/out"), slurp(base + "/err")};
}

void expect_merge_close(const Image& merged, const Image& single, const std::string& what) {
  ASSERT_EQ(merged.pixels.size(), single.pixels.size()) << what;
  size_t bad = 0;
  for (size_t i = 0; i < merged.pixels.size(); ++i)
    if (!(std::abs(merged.pixels[i] - single.pixels[i]) <= 2e-5f * std::abs(single.pixels[i]) + 1e-6f)) ++bad;
  EXPECT_EQ(bad, 0u) << what << ": " << bad << " values outside 2e-5 relative + 1e-6";
}

std::string write_bare_triangle(const std::string& dir, const std::string& name) {
  std::filesystem::create_directories(dir);
  const std::string path = dir + "/" + name;
  std::ofstream(path) << R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],)"
                         R"("meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],)"
                         R"("accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}],)"
                         R"("bufferViews":[{"buffer":0,"byteLength":36}],)"
                         R"("buffers":[{"byteLength":36,"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}]})";
  return path;
}

}  // namespace pxf::test_support
