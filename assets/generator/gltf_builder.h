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
// Texture fields are texture indices from SceneBuilder::addTexture, -1 for none.
struct MaterialDesc {
  std::string name;
  glm::vec4 baseColor{1.0f};
  int baseColorTexture = -1;
  float metallic = 0.0f;
  float roughness = 1.0f;
  int metallicRoughnessTexture = -1;  // G roughness, B metallic
  int normalTexture = -1;
  float normalScale = 1.0f;
  glm::vec3 emissive{0.0f};           // emissiveFactor, each component in [0, 1]
  float emissiveStrength = 1.0f;      // KHR_materials_emissive_strength when != 1
  float transmission = 0.0f;          // KHR_materials_transmission when > 0
  float ior = 1.5f;                   // KHR_materials_ior when transmission > 0 or != 1.5
  bool useSpecular = false;           // KHR_materials_specular
  float specular = 1.0f;
  int specularTexture = -1;           // A channel
  glm::vec3 specularColor{1.0f};
  glm::vec2 uvScale{1.0f};            // KHR_texture_transform on every texture when != 1
  bool doubleSided = false;
  bool alphaMask = false;
  float alphaCutoff = 0.5f;
};

// A dielectric (metallic 0) material of the given color and roughness.
MaterialDesc plainMaterial(const std::string& name, const glm::vec3& color, float roughness = 1.0f);

class SceneBuilder {
 public:
  explicit SceneBuilder(std::string name);

  // Adds a PNG texture (written as <fileStem>.png) with a repeating, mipmapped sampler.
  int addTexture(ByteImage image, const std::string& fileStem);
  int addMaterial(const MaterialDesc& desc);
  // One mesh with one primitive; returns the mesh index.
  int addMesh(const std::string& name, const MeshData& data, int material);
  // A root node instancing `mesh` (rotation as a quaternion).
  int addNode(const std::string& name, int mesh, const glm::vec3& translation = glm::vec3(0.0f),
              const glm::quat& rotation = glm::quat(1, 0, 0, 0), const glm::vec3& scale = glm::vec3(1.0f));
  // Convenience: addMesh + addNode at the origin.
  int addObject(const std::string& name, const MeshData& data, int material);

  void setCamera(const glm::vec3& eye, const glm::vec3& target, float yfov, float aspectRatio);
  // A KHR_lights_punctual directional light; `direction` is where the light travels.
  void addSun(const std::string& name, const glm::vec3& direction, const glm::vec3& color, float intensity);
  // Scene-level render defaults for pxf (scenes[0].extras.pxf).
  void setRenderDefaults(bool allHv, int width, int height);

  // Writes <dir>/<name>.gltf, .bin and the textures; false with a message on failure.
  bool write(const std::string& dir, std::string* error) const;

  const tinygltf::Model& model() const { return model_; }
  size_t triangleCount() const { return triangles_; }

 private:
  int addAccessor(const void* bytes, size_t byteCount, size_t count, int componentType, int type,
                  int target);
  tinygltf::TextureInfo textureInfo(int texture, const MaterialDesc& desc);
  void useExtension(const std::string& extension);

  std::string name_;
  tinygltf::Model model_;
  size_t triangles_ = 0;
};

}  // namespace pxf::scenegen
