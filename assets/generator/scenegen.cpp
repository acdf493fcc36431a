// pxf_scenegen: writes the built-in scenes under assets/.
//
// Regenerate the committed assets (from the repository root):
//   cmake --build build --target pxf_scenegen && build/assets/pxf_scenegen assets
//
// Usage: pxf_scenegen <assets-dir> [scene...]   (no scene names = all scenes)
// Output is deterministic: fixed seeds, integer hashing, no clocks, so the same build writes
// the same bytes every run (assets_tests checks the committed files against a fresh run).
#include <cstdio>
#include <string>

#include "scenes.h"

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s <assets-dir> [scene...]\n", argv[0]);
    return 2;
  }
  const std::string root = argv[1];
  std::vector<std::string> names(argv + 2, argv + argc);
  if (names.empty()) names = pxf::scenegen::scene_names();
  for (const std::string& name : names) {
    try {
      pxf::scenegen::write_scene(name, root);
    } catch (const pxf::Error& e) {
      std::fprintf(stderr, "pxf_scenegen: %s\n", e.what());
      return 1;
    }
    std::printf("wrote %s/%s\n", root.c_str(), name.c_str());
  }
  return 0;
}
