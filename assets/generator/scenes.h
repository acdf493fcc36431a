// The built-in scenes. Each writer puts <name>.gltf, <name>.bin, its PNG textures and, where the
// scene has one, environment.exr into `dir`.
#pragma once
#include <string>
#include <vector>

namespace pxf::scenegen {

bool writeCornell(const std::string& dir, std::string* error);
bool writeAtrium(const std::string& dir, std::string* error);
bool writeKitchen(const std::string& dir, std::string* error);
bool writeEnvmap(const std::string& dir, std::string* error);

// Scene names in generation order.
const std::vector<std::string>& sceneNames();
// Writes scene `name` into <assetsRoot>/<name>/.
bool writeScene(const std::string& name, const std::string& assetsRoot, std::string* error);

}  // namespace pxf::scenegen
