// The scene model shared by the glTF loader, the integrator and the raster range pass.
// Everything is flattened to world space at load time: meshes hold world positions/normals.
// This header has no Embree, GL or tinygltf dependency.
#pragma once
#include <glm/glm.hpp>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace pxf {

enum class Wrap { Repeat, ClampToEdge, MirroredRepeat };

// 4 channels RGBA, top row first, in one of two storages:
// - `texels8` (4 bytes a texel) for 8-bit sources, as stored in the file: RGB sRGB-encoded when
//   `srgb` (decoded to linear at lookup through a 256-entry table), else linear k/255; alpha is
//   always linear k/255. Lookups give exactly the values a float copy decoded at load would hold.
//   The codes never change after loading, so copies of a texture (and of a Scene) share them, and
//   an image used both as sRGB color and as linear data is stored once.
// - `texels` (linear floats) for 16-bit and HDR sources and environment maps.
// Exactly one of them is filled (both empty: an invalid texture).
struct TextureLevel;
struct Texture {
  std::string name;
  int width = 0;
  int height = 0;
  std::vector<glm::vec4> texels;
  std::shared_ptr<const std::vector<unsigned char>> texels8;
  bool srgb = false;  // texels8 only: RGB is sRGB-encoded
  Wrap wrap_s = Wrap::Repeat;
  Wrap wrap_t = Wrap::Repeat;
  bool nearest = false;  // magFilter NEAREST; otherwise bilinear
  // Levels 1, 2, ... (build_texture_mips, scene/texture.h): each half the one before (at least 1
  // texel), box-filtered in linear light, stored like level 0; empty: level 0 alone. Read by lookups with a footprint (path vertices after a rough
  // bounce); shared, like the codes, by copies and by textures with the same texels and encoding.
  std::shared_ptr<const std::vector<TextureLevel>> mips;

  size_t texel_count() const { return width > 0 && height > 0 ? static_cast<size_t>(width) * height : 0; }
  bool is_8bit() const { return texels8 && !texels8->empty(); }
  // True when the storage holds width x height texels.
  bool valid() const {
    size_t n = texel_count();
    return n > 0 && (texels.size() >= n || (texels8 && texels8->size() >= 4 * n));
  }
  // Texel i (row-major) as linear RGBA; i < texel_count() of a valid texture.
  glm::vec4 texel(size_t i) const;
  // Bytes of texel storage, the mip chain's included (shared storage counted in full).
  size_t memory_bytes() const;
};

// One level of a Texture's mip chain, in the storage of its level 0.
struct TextureLevel {
  int width = 0, height = 0;
  std::vector<glm::vec4> texels;
  std::vector<unsigned char> texels8;
};

inline size_t Texture::memory_bytes() const {
  size_t bytes = texels.size() * sizeof(glm::vec4) + (texels8 ? texels8->size() : 0);
  if (mips)
    for (const TextureLevel& level : *mips) bytes += level.texels.size() * sizeof(glm::vec4) + level.texels8.size();
  return bytes;
}

// A material's reference to a texture (glTF textureInfo + KHR_texture_transform).
struct TextureRef {
  int texture = -1;  // index into Scene::textures, -1 = none
  int texcoord = 0;  // 0 or 1
  glm::mat3 transform{1.0f};  // applied to (u, v, 1)
  bool valid() const { return texture >= 0; }
};

enum class AlphaMode { Opaque, Mask, Blend };

// glTF metallic-roughness material (+ emissive_strength, transmission, ior, specular, clearcoat, sheen).
struct Material {
  std::string name;
  glm::vec4 base_color{1.0f};
  TextureRef base_color_texture;
  float metallic = 1.0f;
  float roughness = 1.0f;
  TextureRef metallic_roughness_texture;  // G = roughness, B = metallic
  TextureRef normal_texture;
  float normal_scale = 1.0f;
  glm::vec3 emissive{0.0f};  // already multiplied by KHR_materials_emissive_strength
  TextureRef emissive_texture;
  float transmission = 0.0f;
  TextureRef transmission_texture;  // R
  float ior = 1.5f;
  float specular = 1.0f;                // KHR_materials_specular
  TextureRef specular_texture;          // A
  glm::vec3 specular_color{1.0f};
  TextureRef specular_color_texture;    // RGB
  float clearcoat = 0.0f;               // KHR_materials_clearcoat
  TextureRef clearcoat_texture;         // R
  float clearcoat_roughness = 0.0f;
  TextureRef clearcoat_roughness_texture;  // G
  TextureRef clearcoat_normal_texture;
  float clearcoat_normal_scale = 1.0f;
  glm::vec3 sheen_color{0.0f};          // KHR_materials_sheen
  TextureRef sheen_color_texture;       // RGB (sRGB)
  float sheen_roughness = 0.0f;
  TextureRef sheen_roughness_texture;   // A
  // KHR_materials_volume: absorption coefficient per scene unit, -ln(attenuationColor) /
  // attenuationDistance; 0 = clear or thin-walled (thicknessFactor 0). The medium is the inside
  // of the closed mesh, entered through its front faces.
  glm::vec3 attenuation{0.0f};
  AlphaMode alpha_mode = AlphaMode::Opaque;
  float alpha_cutoff = 0.5f;
  bool double_sided = false;

  bool is_emissive() const { return emissive.x > 0 || emissive.y > 0 || emissive.z > 0; }
  bool has_volume() const { return attenuation.x > 0 || attenuation.y > 0 || attenuation.z > 0; }
};

// One glTF primitive instance in world space. Optional attributes are empty when absent.
struct Mesh {
  std::string name;
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;   // always filled by the loader (computed when missing)
  std::vector<glm::vec4> tangents;  // xyz + handedness w; filled when the material has a normal map
  std::vector<glm::vec2> uv0;
  std::vector<glm::vec2> uv1;
  std::vector<glm::vec4> colors;    // COLOR_0 as RGBA linear
  std::vector<glm::uvec3> triangles;
  int material = 0;                 // index into Scene::materials (the loader adds a default)
};

// glTF camera convention: looks down -Z of its frame, +Y up. Image rows go top to bottom.
// Perspective (yfov) or orthographic (ymag: half the image height in scene units; the image
// aspect sets the width, as it does for perspective).
struct Camera {
  glm::mat4 camera_to_world{1.0f};  // rigid transform (no scale)
  bool orthographic = false;
  float yfov = 0.6911f;             // vertical field of view, radians (perspective)
  float ymag = 1.0f;                // half the view height, scene units (orthographic)
  float znear = 0.01f;
  float zfar = 1000.0f;
  float aspect = 0.0f;              // glTF aspectRatio (0 = unspecified); the image size wins
};

// KHR_lights_punctual. Radiometric: point/spot intensity in W/sr-like units (candela scaled),
// directional in irradiance units (lux scaled), both times color.
struct PunctualLight {
  enum class Type { Point, Spot, Directional };
  Type type = Type::Point;
  std::string name;
  glm::vec3 color{1.0f};
  float intensity = 1.0f;
  glm::vec3 position{0.0f};
  glm::vec3 direction{0.0f, 0.0f, -1.0f};  // direction the light travels (spot/directional)
  float range = 0.0f;                       // 0 = infinite
  float inner_cone = 0.0f;
  float outer_cone = 0.785398f;
};

// Equirectangular environment: u = 0.5 + atan2(d.x, -d.z) / (2 pi), v = acos(d.y) / pi (v = 0 top).
struct Environment {
  Texture image;     // linear RGB radiance
  float strength = 1.0f;
  std::string source;
};

// Render options a scene may carry (e.g. envmap renders with all_hv by default).
struct SceneDefaults {
  bool all_hv = false;
  int width = 0;  // 0 = the tool's default
  int height = 0;
};

struct Scene {
  std::string source;  // file path or built-in name
  std::vector<Mesh> meshes;
  std::vector<Material> materials;
  std::vector<Texture> textures;
  std::vector<PunctualLight> lights;
  std::optional<Environment> environment;
  Camera camera;
  bool automatic_camera = false;  // the file has no camera: frame_scene made it (reframe at the final aspect)
  SceneDefaults defaults;
  std::vector<std::string> warnings;  // what the loader skipped or substituted, one line each
  std::vector<std::string> notes;     // what the loader added that a user should know (the default light)
  uint64_t estimated_load_bytes = 0;  // the loader's memory estimate (LoadEstimate), 0 for a scene not loaded from a file

  size_t triangle_count() const;
};


}  // namespace pxf
