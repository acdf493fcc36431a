#include "scene/gltf_accessor.h"

#include <tiny_gltf.h>

#include <algorithm>
#include <cstring>

#include "image/image.h"

namespace pxf::gltf {
namespace {

// An accessor without a bufferView is all zeros; cap it so a hostile count cannot exhaust memory.
constexpr size_t kMaxZeroAccessorElements = size_t(1) << 26;

[[noreturn]] void fail(const std::string& file, const std::string& what, const std::string& problem) {
  throw Error(file + ": " + what + ": " + problem);
}


int type_components(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR: return 1;
    case TINYGLTF_TYPE_VEC2: return 2;
    case TINYGLTF_TYPE_VEC3: return 3;
    case TINYGLTF_TYPE_VEC4: return 4;
    default: return 0;  // matrices are never vertex attributes we read
  }
}

template <typename T>
T load_unaligned(const unsigned char* p) {
  T value;
  std::memcpy(&value, p, sizeof(T));
  return value;
}

// One component as float, with glTF's normalization rules.
float read_component(const unsigned char* p, int component_type, bool normalized) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return load_unaligned<float>(p);
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      float v = load_unaligned<int8_t>(p);
      return normalized ? std::max(v / 127.0f, -1.0f) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: {
      float v = load_unaligned<uint8_t>(p);
      return normalized ? v / 255.0f : v;
    }
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      float v = load_unaligned<int16_t>(p);
      return normalized ? std::max(v / 32767.0f, -1.0f) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      float v = load_unaligned<uint16_t>(p);
      return normalized ? v / 65535.0f : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
      float v = static_cast<float>(load_unaligned<uint32_t>(p));
      return normalized ? v / 4294967295.0f : v;
    }
    default: return 0.0f;
  }
}

uint32_t read_index(const unsigned char* p, int component_type) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return load_unaligned<uint8_t>(p);
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return load_unaligned<uint16_t>(p);
    default: return load_unaligned<uint32_t>(p);
  }
}

// Strided elements inside a validated buffer view.
struct ElementView {
  const unsigned char* data = nullptr;
  size_t stride = 0;
};

ElementView element_view(const tinygltf::Model& model, int view_index, size_t byte_offset,
                         size_t count, size_t element_size, size_t explicit_stride,
                         const std::string& file, const std::string& what) {
  ByteRange range = buffer_view_bytes(model, view_index, file, what);
  size_t stride = explicit_stride ? explicit_stride : element_size;
  if (stride < element_size) fail(file, what, "byteStride " + std::to_string(stride) + " is smaller than an element");
  if (count == 0) return {range.data, stride};
  // Overflow-safe: last element end = byte_offset + stride * (count - 1) + element_size.
  if (byte_offset > range.size || (count - 1) > (range.size - byte_offset) / stride ||
      byte_offset + stride * (count - 1) + element_size > range.size)
    fail(file, what, "accessor reads past the end of bufferView " + std::to_string(view_index));
  return {range.data + byte_offset, stride};
}

void apply_sparse(const tinygltf::Model& model, const tinygltf::Accessor& accessor, int components,
                  std::vector<float>& out, const std::string& file, const std::string& what) {
  const auto& sparse = accessor.sparse;
  if (sparse.count <= 0) return;
  size_t count = static_cast<size_t>(sparse.count);
  int index_size = component_size(sparse.indices.componentType);
  if (index_size == 0 || sparse.indices.componentType == TINYGLTF_COMPONENT_TYPE_BYTE ||
      sparse.indices.componentType == TINYGLTF_COMPONENT_TYPE_SHORT ||
      sparse.indices.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT)
    fail(file, what, "sparse indices have an invalid component type");
  if (sparse.indices.byteOffset < 0 || sparse.values.byteOffset < 0) fail(file, what, "negative sparse byteOffset");
  size_t value_size = static_cast<size_t>(component_size(accessor.componentType)) * components;
  ElementView indices = element_view(model, sparse.indices.bufferView, sparse.indices.byteOffset, count,
                                     index_size, 0, file, what + " sparse indices");
  ElementView values = element_view(model, sparse.values.bufferView, sparse.values.byteOffset, count,
                                    value_size, 0, file, what + " sparse values");
  size_t elements = out.size() / components;
  for (size_t i = 0; i < count; ++i) {
    uint32_t target = read_index(indices.data + i * indices.stride, sparse.indices.componentType);
    if (target >= elements) fail(file, what, "sparse index " + std::to_string(target) + " out of range");
    for (int c = 0; c < components; ++c)
      out[target * components + c] = read_component(values.data + i * values.stride + c * component_size(accessor.componentType),
                                                    accessor.componentType, accessor.normalized);
  }
}

// The view's byteStride, 0 (tightly packed) for an invalid view, which element_view then rejects.
size_t view_stride(const tinygltf::Model& model, int view_index) {
  if (view_index < 0 || view_index >= static_cast<int>(model.bufferViews.size())) return 0;
  return model.bufferViews[view_index].byteStride;
}

const tinygltf::Accessor& accessor_at(const tinygltf::Model& model, int index, const std::string& file,
                                      const std::string& what) {
  if (index < 0 || index >= static_cast<int>(model.accessors.size()))
    fail(file, what, "accessor " + std::to_string(index) + " out of range (" +
                         std::to_string(model.accessors.size()) + " accessors)");
  return model.accessors[index];
}

}  // namespace

int component_size(int component_type) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return 4;
    default: return 0;
  }
}

ByteRange buffer_view_bytes(const tinygltf::Model& model, int view_index, const std::string& file,
                            const std::string& what) {
  if (view_index < 0 || view_index >= static_cast<int>(model.bufferViews.size()))
    fail(file, what, "bufferView " + std::to_string(view_index) + " out of range");
  const tinygltf::BufferView& view = model.bufferViews[view_index];
  if (view.buffer < 0 || view.buffer >= static_cast<int>(model.buffers.size()))
    fail(file, what, "buffer " + std::to_string(view.buffer) + " out of range");
  const tinygltf::Buffer& buffer = model.buffers[view.buffer];
  size_t size = buffer.data.size();
  if (view.byteOffset > size || view.byteLength > size - view.byteOffset)
    fail(file, what, "bufferView " + std::to_string(view_index) + " exceeds buffer " +
                         std::to_string(view.buffer) + " (" + std::to_string(size) + " bytes)");
  return {buffer.data.data() + view.byteOffset, view.byteLength};
}

std::vector<float> read_floats(const tinygltf::Model& model, int index, const std::string& file,
                               const std::string& what, std::vector<int> allowed_components,
                               int* components_out) {
  const tinygltf::Accessor& accessor = accessor_at(model, index, file, what);
  int components = type_components(accessor.type);
  if (std::find(allowed_components.begin(), allowed_components.end(), components) == allowed_components.end())
    fail(file, what, "accessor " + std::to_string(index) + " has an unexpected type");
  int csize = component_size(accessor.componentType);
  if (csize == 0) fail(file, what, "accessor " + std::to_string(index) + " has an invalid componentType");
  if (components_out) *components_out = components;
  size_t count = accessor.count;
  std::vector<float> out;
  if (accessor.bufferView < 0) {
    if (count > kMaxZeroAccessorElements) fail(file, what, "accessor count is implausibly large");
    out.assign(count * components, 0.0f);
  } else {
    size_t element_size = static_cast<size_t>(csize) * components;
    ElementView elements = element_view(model, accessor.bufferView, accessor.byteOffset, count, element_size,
                                        view_stride(model, accessor.bufferView), file, what);
    out.resize(count * components);
    for (size_t i = 0; i < count; ++i) {
      const unsigned char* p = elements.data + i * elements.stride;
      for (int c = 0; c < components; ++c)
        out[i * components + c] = read_component(p + c * csize, accessor.componentType, accessor.normalized);
    }
  }
  if (accessor.sparse.isSparse) apply_sparse(model, accessor, components, out, file, what);
  return out;
}

std::vector<glm::vec2> read_vec2(const tinygltf::Model& model, int index, const std::string& file,
                                 const std::string& what) {
  std::vector<float> f = read_floats(model, index, file, what, {2});
  std::vector<glm::vec2> out(f.size() / 2);
  for (size_t i = 0; i < out.size(); ++i) out[i] = {f[2 * i], f[2 * i + 1]};
  return out;
}

std::vector<glm::vec3> read_vec3(const tinygltf::Model& model, int index, const std::string& file,
                                 const std::string& what) {
  std::vector<float> f = read_floats(model, index, file, what, {3});
  std::vector<glm::vec3> out(f.size() / 3);
  for (size_t i = 0; i < out.size(); ++i) out[i] = {f[3 * i], f[3 * i + 1], f[3 * i + 2]};
  return out;
}

std::vector<glm::vec4> read_vec4(const tinygltf::Model& model, int index, const std::string& file,
                                 const std::string& what) {
  std::vector<float> f = read_floats(model, index, file, what, {4});
  std::vector<glm::vec4> out(f.size() / 4);
  for (size_t i = 0; i < out.size(); ++i) out[i] = {f[4 * i], f[4 * i + 1], f[4 * i + 2], f[4 * i + 3]};
  return out;
}

std::vector<glm::vec4> read_color(const tinygltf::Model& model, int index, const std::string& file,
                                  const std::string& what) {
  int components = 0;
  std::vector<float> f = read_floats(model, index, file, what, {3, 4}, &components);
  std::vector<glm::vec4> out(f.size() / components);
  for (size_t i = 0; i < out.size(); ++i) {
    const float* p = &f[i * components];
    out[i] = {p[0], p[1], p[2], components == 4 ? p[3] : 1.0f};
  }
  return out;
}

std::vector<uint32_t> read_indices(const tinygltf::Model& model, int index, const std::string& file,
                                   const std::string& what) {
  const tinygltf::Accessor& accessor = accessor_at(model, index, file, what);
  int type = accessor.componentType;
  if (type_components(accessor.type) != 1 ||
      (type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
       type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT))
    fail(file, what, "index accessor " + std::to_string(index) + " is not an unsigned integer scalar");
  if (accessor.sparse.isSparse || accessor.bufferView < 0) {
    // Rare; reuse the float path (exact for indices below 2^24, plenty for a renderer's meshes).
    std::vector<float> f = read_floats(model, index, file, what, {1});
    return std::vector<uint32_t>(f.begin(), f.end());
  }
  int csize = component_size(type);
  ElementView elements = element_view(model, accessor.bufferView, accessor.byteOffset, accessor.count, csize,
                                      view_stride(model, accessor.bufferView), file, what);
  std::vector<uint32_t> out(accessor.count);
  for (size_t i = 0; i < out.size(); ++i) out[i] = read_index(elements.data + i * elements.stride, type);
  return out;
}

}  // namespace pxf::gltf
