#include "scene/gltf_draco.h"

#include <draco/compression/decode.h>
#include <tiny_gltf.h>

#include <cstdint>
#include <cstring>
#include <memory>
#include <new>

#include "core/error.h"
#include "scene/gltf_accessor.h"

namespace pxf::gltf {
namespace {

constexpr const char* kExtension = "KHR_draco_mesh_compression";

[[noreturn]] void fail(const std::string& file, const std::string& what, const std::string& problem) {
  throw Error(file + ": " + what + ": " + problem);
}

int integer_member(const tinygltf::Value& object, const char* key) {
  const tinygltf::Value& v = object.Get(key);
  if (!v.IsNumber()) return -1;
  const double d = v.GetNumberAsDouble();
  return d >= 0 && d <= 2147483647.0 && d == static_cast<int>(d) ? static_cast<int>(d) : -1;
}

std::unique_ptr<draco::Mesh> decode_mesh(const ByteRange& bytes, const std::string& file, const std::string& what) {
  draco::DecoderBuffer buffer;
  buffer.Init(reinterpret_cast<const char*>(bytes.data), bytes.size);
  draco::Decoder decoder;
  try {
    auto decoded = decoder.DecodeMeshFromBuffer(&buffer);
    if (!decoded.ok()) fail(file, what, "Draco data could not be decoded (" + decoded.status().error_msg_string() + ")");
    if (!decoded.value()) fail(file, what, "Draco data decoded to no mesh");
    return std::move(decoded).value();
  } catch (const std::bad_alloc&) {
    fail(file, what, "Draco data could not be decoded (it asks for more memory than there is)");
  } catch (const std::length_error&) {
    fail(file, what, "Draco data could not be decoded (a size out of range)");
  }
}

// One point's components converted to the accessor's component type and stored at `out`.
template <typename T>
bool store_value(const draco::PointAttribute& attribute, draco::AttributeValueIndex index, int components,
                 unsigned char* out) {
  T values[4];
  if (!attribute.ConvertValue<T>(index, static_cast<int8_t>(components), values)) return false;
  std::memcpy(out, values, sizeof(T) * components);
  return true;
}

bool store_point(const draco::PointAttribute& attribute, draco::AttributeValueIndex index, int component_type,
                 int components, unsigned char* out) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: return store_value<int8_t>(attribute, index, components, out);
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return store_value<uint8_t>(attribute, index, components, out);
    case TINYGLTF_COMPONENT_TYPE_SHORT: return store_value<int16_t>(attribute, index, components, out);
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return store_value<uint16_t>(attribute, index, components, out);
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return store_value<uint32_t>(attribute, index, components, out);
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return store_value<float>(attribute, index, components, out);
    default: return false;
  }
}

// A decoded array that becomes one bufferView and accessor of the new buffer.
struct DecodedArray {
  std::string semantic;  // "" for the indices
  tinygltf::Accessor accessor;
  std::vector<unsigned char> bytes;
};

DecodedArray decode_attribute(const draco::Mesh& mesh, const tinygltf::Accessor& declared, const std::string& semantic,
                              int unique_id, const std::string& file, const std::string& what) {
  const std::string label = what + " " + semantic;
  const draco::PointAttribute* attribute = unique_id >= 0 ? mesh.GetAttributeByUniqueId(unique_id) : nullptr;
  if (!attribute) fail(file, label, "the Draco data has no attribute " + std::to_string(unique_id));
  const int components = tinygltf::GetNumComponentsInType(declared.type);
  const int bytes_per_component = component_size(declared.componentType);
  if (components < 1 || components > 4 || bytes_per_component == 0)
    fail(file, label, "accessor type or componentType is not a vertex attribute's");
  if (attribute->num_components() != components)
    fail(file, label, "the Draco attribute has " + std::to_string(attribute->num_components()) +
                          " components, the accessor " + std::to_string(components));
  const size_t points = mesh.num_points();
  if (declared.count != points)
    fail(file, label, "the Draco data decodes to " + std::to_string(points) + " vertices, the accessor says " +
                          std::to_string(declared.count));
  if (!attribute->is_mapping_identity() && attribute->indices_map_size() < points)
    fail(file, label, "the Draco attribute maps fewer points than the mesh has");
  DecodedArray out;
  out.semantic = semantic;
  out.accessor = declared;
  const size_t element = static_cast<size_t>(components) * bytes_per_component;
  out.bytes.resize(points * element);
  for (size_t p = 0; p < points; ++p) {
    const draco::AttributeValueIndex value = attribute->mapped_index(draco::PointIndex(static_cast<uint32_t>(p)));
    if (value.value() >= attribute->size() ||
        !store_point(*attribute, value, declared.componentType, components, &out.bytes[p * element]))
      fail(file, label, "a Draco attribute value is missing or does not fit the accessor's component type");
  }
  return out;
}

DecodedArray decode_indices(const draco::Mesh& mesh, const tinygltf::Model& model, const tinygltf::Primitive& primitive,
                            const std::string& file, const std::string& what) {
  const size_t faces = mesh.num_faces(), points = mesh.num_points();
  if (primitive.indices >= 0) {
    // The triangles the loader counted against its limits: a list's count / 3, a strip's or fan's count - 2.
    const size_t count = model.accessors[primitive.indices].count;
    const bool list = primitive.mode < 0 || primitive.mode == TINYGLTF_MODE_TRIANGLES;
    const size_t declared = list ? (count % 3 == 0 ? count / 3 : SIZE_MAX) : (count >= 3 ? count - 2 : 0);
    if (declared != faces)
      fail(file, what + " indices", "the Draco data decodes to " + std::to_string(faces) + " triangles, the accessor's " +
                                        std::to_string(count) + " indices say otherwise");
  } else if (faces > points / 3) {
    fail(file, what, "the Draco data decodes to " + std::to_string(faces) + " triangles, more than its " +
                         std::to_string(points) + " vertices make without indices");
  }
  DecodedArray out;
  out.accessor.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
  out.accessor.type = TINYGLTF_TYPE_SCALAR;
  out.accessor.count = 3 * faces;
  out.bytes.resize(out.accessor.count * sizeof(uint32_t));
  for (draco::FaceIndex f(0); f < mesh.num_faces(); ++f)
    for (int corner = 0; corner < 3; ++corner) {
      const uint32_t vertex = mesh.face(f)[corner].value();
      if (vertex >= points) fail(file, what + " indices", "a Draco face names vertex " + std::to_string(vertex) + " of " + std::to_string(points));
      std::memcpy(&out.bytes[(3 * static_cast<size_t>(f.value()) + corner) * sizeof(uint32_t)], &vertex, sizeof vertex);
    }
  return out;
}

// Each decoded array becomes a buffer of its own (moved, not copied), a bufferView and an
// accessor; the primitive names the new accessors.
void install(tinygltf::Model& model, tinygltf::Primitive& primitive, std::vector<DecodedArray>& arrays) {
  for (DecodedArray& array : arrays) {
    tinygltf::BufferView view;
    view.buffer = static_cast<int>(model.buffers.size());
    view.byteLength = array.bytes.size();
    model.buffers.emplace_back();
    model.buffers.back().data = std::move(array.bytes);
    model.bufferViews.push_back(view);
    array.accessor.bufferView = static_cast<int>(model.bufferViews.size()) - 1;
    array.accessor.byteOffset = 0;
    array.accessor.sparse.isSparse = false;  // the decoded values are the whole accessor
    array.accessor.sparse.count = 0;
    model.accessors.push_back(array.accessor);
    const int accessor_index = static_cast<int>(model.accessors.size()) - 1;
    if (array.semantic.empty()) primitive.indices = accessor_index;
    else primitive.attributes[array.semantic] = accessor_index;
  }
  primitive.mode = TINYGLTF_MODE_TRIANGLES;
}

void decode_primitive(tinygltf::Model& model, tinygltf::Primitive& primitive, const tinygltf::Value& extension,
                      const std::string& file, const std::string& what) {
  const int view = integer_member(extension, "bufferView");
  if (view < 0) fail(file, what, kExtension + std::string(" has no valid bufferView"));
  const tinygltf::Value& ids = extension.Get("attributes");
  if (!ids.IsObject()) fail(file, what, kExtension + std::string(" has no attributes object"));
  if (primitive.indices >= static_cast<int>(model.accessors.size())) fail(file, what, "indices accessor out of range");
  std::unique_ptr<draco::Mesh> mesh;
  mesh = decode_mesh(buffer_view_bytes(model, view, file, what + " Draco bufferView"), file, what);
  std::vector<DecodedArray> arrays;
  for (const auto& [semantic, accessor] : primitive.attributes) {
    if (!ids.Has(semantic)) continue;  // stored uncompressed beside the Draco data
    if (accessor < 0 || accessor >= static_cast<int>(model.accessors.size()))
      fail(file, what + " " + semantic, "accessor " + std::to_string(accessor) + " out of range");
    arrays.push_back(decode_attribute(*mesh, model.accessors[accessor], semantic, integer_member(ids, semantic.c_str()), file, what));
  }
  arrays.push_back(decode_indices(*mesh, model, primitive, file, what));
  mesh.reset();  // before the model's buffers grow: the Draco bytes are no longer read
  install(model, primitive, arrays);
}

}  // namespace

void decode_draco_primitives(tinygltf::Model& model, const std::string& file) {
  for (size_t m = 0; m < model.meshes.size(); ++m)
    for (size_t p = 0; p < model.meshes[m].primitives.size(); ++p) {
      tinygltf::Primitive& primitive = model.meshes[m].primitives[p];
      const auto found = primitive.extensions.find(kExtension);
      if (found == primitive.extensions.end()) continue;
      // Points and lines are skipped by the loader (with a warning); Draco only decodes triangles.
      const int mode = primitive.mode;
      if (mode >= 0 && mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
          mode != TINYGLTF_MODE_TRIANGLE_FAN)
        continue;
      const std::string what = "mesh " + std::to_string(m) + " primitive " + std::to_string(p);
      if (!found->second.IsObject()) fail(file, what, std::string(kExtension) + " is not an object");
      decode_primitive(model, primitive, found->second, file, what);
    }
}

}  // namespace pxf::gltf
