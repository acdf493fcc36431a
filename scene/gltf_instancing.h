// EXT_mesh_gpu_instancing: a node's mesh drawn once per instance, each with the transform of its
// TRANSLATION, ROTATION and SCALE accessors (T * R * S, applied after the node's own world
// transform). The path tracer flattens the instances into meshes like any other node's.
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>
#include <glm/glm.hpp>

namespace tinygltf {
class Model;
class Node;
}

namespace pxf::gltf {

// How many times the node instances its mesh, from the accessors' counts alone (no data read):
// 1 without the extension; the largest count when they disagree (reading them then fails).
uint64_t instance_count(const tinygltf::Model& model, const tinygltf::Node& node);

// The node's instance transforms, or nothing without the extension. Throws pxf::Error for
// accessors of different counts or unreadable ones.
std::optional<std::vector<glm::mat4>> instance_transforms(const tinygltf::Model& model, const tinygltf::Node& node,
                                                           const std::string& file, const std::string& what);

}  // namespace pxf::gltf
