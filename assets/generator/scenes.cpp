#include "scenes.h"

#include <filesystem>

namespace pxf::scenegen {

const std::vector<std::string>& sceneNames() {
  static const std::vector<std::string> names = {"cornell", "atrium", "kitchen", "envmap"};
  return names;
}

bool writeScene(const std::string& name, const std::string& assetsRoot, std::string* error) {
  const std::string dir = (std::filesystem::path(assetsRoot) / name).string();
  if (name == "cornell") return writeCornell(dir, error);
  if (name == "atrium") return writeAtrium(dir, error);
  if (name == "kitchen") return writeKitchen(dir, error);
  if (name == "envmap") return writeEnvmap(dir, error);
  *error = "unknown scene '" + name + "'";
  return false;
}

}  // namespace pxf::scenegen
