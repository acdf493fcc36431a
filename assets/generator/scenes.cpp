#include "scenes.h"

#include <algorithm>
#include <filesystem>

namespace pxf::scenegen {

const std::vector<std::string>& scene_names() {
  static const std::vector<std::string> names = {"cornell", "atrium", "kitchen", "envmap", "product", "window"};
  return names;
}

void write_scene(const std::string& name, const std::string& assets_root) {
  const std::string dir = (std::filesystem::path(assets_root) / name).string();
  if (name == "cornell") return write_cornell(dir);
  if (name == "atrium") return write_atrium(dir);
  if (name == "kitchen") return write_kitchen(dir);
  if (name == "envmap") return write_envmap(dir);
  if (name == "product") return write_product(dir);
  if (name == "window") return write_window(dir);
  throw Error("unknown scene '" + name + "'");
}

void write_environment(const std::string& dir, Image rgb) {
  for (float& v : rgb.pixels) v = std::clamp(v, 0.0f, 60000.0f);
  write_exr((std::filesystem::path(dir) / "environment.exr").string(), rgb, /*half=*/true);
}

}  // namespace pxf::scenegen
