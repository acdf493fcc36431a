#include "scene/gltf_instancing.h"

#include <tiny_gltf.h>

#include <algorithm>
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include "core/error.h"
#include "scene/gltf_accessor.h"

namespace pxf::gltf {
namespace {

constexpr const char* kExtension = "EXT_mesh_gpu_instancing";
constexpr const char* kSemantics[] = {"TRANSLATION", "ROTATION", "SCALE"};

const tinygltf::Value* instancing_attributes(const tinygltf::Node& node) {
  const auto found = node.extensions.find(kExtension);
  if (found == node.extensions.end() || !found->second.IsObject()) return nullptr;
  const tinygltf::Value& attributes = found->second.Get("attributes");
  return attributes.IsObject() ? &attributes : nullptr;
}

// The accessor index of `semantic`; -1 when absent, -2 when not a valid index.
int accessor_of(const tinygltf::Value& attributes, const char* semantic) {
  if (!attributes.Has(semantic)) return -1;
  const tinygltf::Value& v = attributes.Get(semantic);
  if (!v.IsNumber()) return -2;
  const double d = v.GetNumberAsDouble();
  return d >= 0 && d <= 2147483647.0 && d == static_cast<int>(d) ? static_cast<int>(d) : -2;
}

glm::mat4 rotation_matrix(glm::vec4 xyzw) {
  const glm::quat q(xyzw.w, xyzw.x, xyzw.y, xyzw.z);
  const float length = glm::length(q);
  return length > 0.0f && std::isfinite(length) ? glm::mat4_cast(q / length) : glm::mat4(1.0f);
}

}  // namespace

uint64_t instance_count(const tinygltf::Model& model, const tinygltf::Node& node) {
  const tinygltf::Value* attributes = instancing_attributes(node);
  if (!attributes) return 1;
  uint64_t count = 0;
  for (const char* semantic : kSemantics) {
    const int accessor = accessor_of(*attributes, semantic);
    if (accessor >= 0 && accessor < static_cast<int>(model.accessors.size()))
      count = std::max<uint64_t>(count, model.accessors[accessor].count);
  }
  return count;
}

std::optional<std::vector<glm::mat4>> instance_transforms(const tinygltf::Model& model, const tinygltf::Node& node,
                                                           const std::string& file, const std::string& what) {
  const tinygltf::Value* attributes = instancing_attributes(node);
  if (!attributes) return std::nullopt;
  std::vector<glm::vec3> translations, scales;
  std::vector<glm::vec4> rotations;
  size_t count = 0;
  bool first = true;
  auto read = [&](const char* semantic, auto reader, auto& out) {
    const int accessor = accessor_of(*attributes, semantic);
    if (accessor == -1) return;
    const std::string label = what + " " + kExtension + " " + semantic;
    if (accessor == -2) throw Error(file + ": " + label + ": not an accessor index");
    out = reader(model, accessor, file, label);
    if (!first && out.size() != count)
      throw Error(file + ": " + label + ": " + std::to_string(out.size()) + " instances, the other attributes have " +
                  std::to_string(count));
    count = out.size();
    first = false;
  };
  read("TRANSLATION", read_vec3, translations);
  read("ROTATION", read_vec4, rotations);
  read("SCALE", read_vec3, scales);
  std::vector<glm::mat4> transforms(count, glm::mat4(1.0f));
  for (size_t i = 0; i < count; ++i) {
    glm::mat4& m = transforms[i];
    if (!translations.empty()) m = glm::translate(m, translations[i]);
    if (!rotations.empty()) m *= rotation_matrix(rotations[i]);
    if (!scales.empty()) m = glm::scale(m, scales[i]);
  }
  return transforms;
}

}  // namespace pxf::gltf
