// Bounds-checked reading of glTF accessors (tinygltf trusts the file's offsets; we do not).
// Every problem throws pxf::Error("<file>: <problem>").
#pragma once
#include <cstdint>
#include <string>
#include <vector>
#include <glm/glm.hpp>

namespace tinygltf {
class Model;
}

namespace pxf::gltf {

// Reads accessor `index` as float tuples (integer components converted, normalized ones mapped to
// [0,1] / [-1,1] as glTF defines). `allowed_components` lists the accepted tuple sizes (e.g. {3,4}
// for COLOR_0); `components` receives the accessor's own size. Sparse accessors are supported.
std::vector<float> read_floats(const tinygltf::Model& model, int index, const std::string& file,
                               const std::string& what, std::vector<int> allowed_components,
                               int* components = nullptr);

std::vector<glm::vec2> read_vec2(const tinygltf::Model& model, int index, const std::string& file,
                                 const std::string& what);
std::vector<glm::vec3> read_vec3(const tinygltf::Model& model, int index, const std::string& file,
                                 const std::string& what);
std::vector<glm::vec4> read_vec4(const tinygltf::Model& model, int index, const std::string& file,
                                 const std::string& what);
// COLOR_0: vec3 (alpha = 1) or vec4.
std::vector<glm::vec4> read_color(const tinygltf::Model& model, int index, const std::string& file,
                                  const std::string& what);
// Bytes of one component of a glTF componentType (5120..5126); 0 for an unknown type.
int component_size(int component_type);

// Index accessor (unsigned byte/short/int scalars).
std::vector<uint32_t> read_indices(const tinygltf::Model& model, int index, const std::string& file,
                                   const std::string& what);

// Validated [begin, begin + byte_length) of bufferView `view` inside its buffer.
struct ByteRange {
  const unsigned char* data = nullptr;
  size_t size = 0;
};
ByteRange buffer_view_bytes(const tinygltf::Model& model, int view, const std::string& file,
                            const std::string& what);

}  // namespace pxf::gltf
