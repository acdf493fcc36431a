// Loading a scene: the built-in scenes, glTF/GLB files with every supported extension, and the
// limits and memory estimate that refuse a scene before anything large is allocated.
#pragma once
#include <cstdint>
#include <string>
#include <vector>
#include "core/memory.h"  // available_memory_bytes, which LoadLimits defaults to
#include "scene/default_light.h"
#include "scene/scene.h"

namespace pxf {

// What a scene may demand. The loader counts the instanced triangles (every mesh once per node
// that references it) and reads the used images' headers before it reads any geometry or decodes
// any texture; over a cap, or with an estimate over the available memory, it refuses.
struct LoadLimits {
  static constexpr int kDefaultMaxTextureSize = 16384;
  static constexpr uint64_t kDefaultMaxTriangles = 100'000'000;
  int max_texture_size = kDefaultMaxTextureSize;  // texels, per side
  uint64_t max_triangles = kDefaultMaxTriangles;  // instanced triangles in the whole scene
  uint64_t available_memory = 0;                  // bytes; 0 = what the system reports now
};

// The loader's memory estimate for a scene, in bytes: what the loaded scene, the BVH, the raster
// pass's copies and draws and the decoding need at the peak (docs/scenes.md, "Resource limits").
struct LoadEstimate {
  uint64_t vertices = 0, triangles = 0;  // instanced
  uint64_t meshes = 0;                   // instanced primitives: each a Mesh, a BVH geometry, a draw
  uint64_t lights = 0;                   // instanced punctual lights
  uint64_t texture_bytes = 0;            // stored texels of the used textures (level 0)
  uint64_t largest_decode_bytes = 0;     // the largest image's decoding buffers
  uint64_t environment_texels = 0;       // the environment map's (--env or the scene's own)
  uint64_t decoded_buffer_bytes = 0;     // EXT_meshopt_compression views, decoded and kept while loading
  uint64_t bytes() const;
};

// The glTF/GLB file and the files its uris name (buffers, images) are read up to 4 GiB - 1: tinygltf
// takes a file's length as an unsigned int, and a GLB stores its lengths in 32 bits.
constexpr uint64_t kMaxGltfFileBytes = 0xffffffff;

// Loads a glTF/GLB file or a built-in scene name ("cornell", ...); throws pxf::Error naming the
// file and the problem. `env_path` (optional) replaces the environment with an equirectangular
// EXR or Radiance .hdr (checked before the scene loads). A scene without any light gets the
// built-in `default_light` environment (Scene::notes says so); with None a warning says it is black.
// Before anything large is allocated, the loader checks `limits` (see LoadLimits) and refuses
// with a one-line error naming the file and the limit.
Scene load_scene(const std::string& name_or_path, const std::string& env_path = "", float env_strength = 1.0f,
                 DefaultLight default_light = DefaultLight::None, const LoadLimits& limits = {});
// The same from a glTF/GLB already in memory (the fuzzer's entry point); `name` prefixes errors and
// relative uris resolve against `base_dir`.
Scene load_scene_from_memory(const std::vector<unsigned char>& bytes, const std::string& name,
                             const std::string& base_dir, const LoadLimits& limits = {});
// The built-in scenes: name and one-line description.
struct BuiltinScene { std::string name, description, path; };
std::vector<BuiltinScene> builtin_scenes();
// The folder of the built-in scenes: PREFIX/share/pxf/assets beside an installed pxf (found from
// the running executable's path), else the source tree's assets/.
std::string builtin_assets_dir();

}  // namespace pxf
