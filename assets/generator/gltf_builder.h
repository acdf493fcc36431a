// Assembles a glTF 2.0 model (meshes, materials, textures, camera, lights) in memory and writes
// it as <dir>/<name>.gltf + <name>.bin + PNG textures. Tracks which extensions the materials
// use so that extensionsUsed lists exactly those.
#pragma once
#include <tiny_gltf.h>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <set>
#include <string>
#include <vector>

#include "mesh.h"
#include "texture.h"

namespace pxf::scenegen {

// A material in the renderer's vocabulary (glTF metallic-roughness + the supported extensions).
// Texture fields are texture indices from SceneBuilder::add_texture, -1 for none.
struct MaterialDesc {
  std::string name;
  glm::vec4 base_color{1.0f};
  int base_color_texture = -1;
  float metallic = 0.0f;
  float roughness = 1.0f;
  int metallic_roughness_texture = -1;  // G roughness, B metallic
  int normal_texture = -1;
  float normal_scale = 1.0f;
  glm::vec3 emissive{0.0f};           // emissiveFactor, each component in [0, 1]
  float emissive_strength = 1.0f;      // KHR_materials_emissive_strength when != 1
  float transmission = 0.0f;          // KHR_materials_transmission when > 0
  float ior = 1.5f;                   // KHR_materials_ior when transmission > 0 or != 1.5
  bool use_specular = false;           // KHR_materials_specular
  float specular = 1.0f;
  int specular_texture = -1;           // A channel
  glm::vec3 specular_color{1.0f};
  float clearcoat = 0.0f;              // KHR_materials_clearcoat when > 0 (a lacquer over the base)
  float clearcoat_roughness = 0.0f;
  glm::vec2 uv_scale{1.0f};            // KHR_texture_transform on every texture when != 1
  bool doubleSided = false;
  bool alpha_mask = false;
  float alpha_cutoff = 0.5f;
};

// A dielectric (metallic 0) material of the given color and roughness.
MaterialDesc plain_material(const std::string& name, const glm::vec3& color, float roughness = 1.0f);

class SceneBuilder {
 public:
  explicit SceneBuilder(std::string name);

  // Adds a PNG texture (written as <file_stem>.png) with a repeating, mipmapped sampler.
  int add_texture(ByteImage image, const std::string& file_stem);
  int add_material(const MaterialDesc& desc);
  // One mesh with one primitive; returns the mesh index.
  int add_mesh(const std::string& name, const MeshData& data, int material);
  // A root node instancing `mesh` (rotation as a quaternion).
  int add_node(const std::string& name, int mesh, const glm::vec3& translation = glm::vec3(0.0f),
               const glm::quat& rotation = glm::quat(1, 0, 0, 0), const glm::vec3& scale = glm::vec3(1.0f));
  // Convenience: add_mesh + add_node at the origin.
  int add_object(const std::string& name, const MeshData& data, int material);

  void set_camera(const glm::vec3& eye, const glm::vec3& target, float yfov, float aspect_ratio);
  // A KHR_lights_punctual directional light; `direction` is where the light travels.
  void add_sun(const std::string& name, const glm::vec3& direction, const glm::vec3& color, float intensity);
  // Scene-level render defaults for pxf (scenes[0].extras.pxf).
  void set_render_defaults(bool all_hv, int width, int height);

  // Writes <dir>/<name>.gltf, .bin and the textures; throws pxf::Error naming the file on failure.
  void write(const std::string& dir) const;

  const tinygltf::Model& model() const { return model_; }
  size_t triangle_count() const { return triangles_; }

 private:
  int add_accessor(const void* bytes, size_t byte_count, size_t count, int component_type, int type,
                   int target);
  tinygltf::TextureInfo texture_info(int texture, const MaterialDesc& desc);
  void use_extension(const std::string& extension);

  std::string name_;
  tinygltf::Model model_;
  size_t triangles_ = 0;
};

}  // namespace pxf::scenegen
