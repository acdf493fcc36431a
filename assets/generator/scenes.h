// The built-in scenes. Each writer puts <name>.gltf, <name>.bin, its PNG textures and, where the
// scene has one, environment.exr into `dir`.
#pragma once
#include <string>
#include <vector>

#include "texture.h"

namespace pxf::scenegen {

// Each throws pxf::Error naming the file it could not write.
void write_cornell(const std::string& dir);
void write_atrium(const std::string& dir);
void write_kitchen(const std::string& dir);
void write_envmap(const std::string& dir);
void write_product(const std::string& dir);
void write_window(const std::string& dir);

// Scene names in generation order.
const std::vector<std::string>& scene_names();
// Writes scene `name` into <assets_root>/<name>/; pxf::Error for an unknown name or a failed write.
void write_scene(const std::string& name, const std::string& assets_root);

// <dir>/environment.exr, a scene's sky: RGB half floats, clamped to [0, 60000] (half floats
// overflow to infinity above 65504; no sky needs more).
void write_environment(const std::string& dir, Image rgb);

}  // namespace pxf::scenegen
