#include "scene/gltf_prepass.h"

#include <tiny_gltf.h>

#include <algorithm>
#include <cstring>
#include <nlohmann/json.hpp>

#include "core/error.h"

namespace pxf::gltf {
namespace {

using json = nlohmann::json;

constexpr const char* kDraco = "KHR_draco_mesh_compression";
constexpr const char* kMeshopt = "EXT_meshopt_compression";

bool mentions(const char* text, size_t size, const char* word) {
  const size_t n = std::strlen(word);
  return std::search(text, text + size, word, word + n) != text + size;
}

// The JSON text of a .gltf, or of a GLB's first chunk (length at byte 12, text from byte 20;
// tinygltf names a malformed header).
struct JsonText {
  const char* data = nullptr;
  size_t size = 0;
};
JsonText json_text(const unsigned char* data, size_t size, bool binary) {
  if (!binary) return {reinterpret_cast<const char*>(data), size};
  if (size < 20) return {};
  uint32_t length = 0;
  std::memcpy(&length, data + 12, sizeof length);
  return {reinterpret_cast<const char*>(data) + 20, std::min<size_t>(length, size - 20)};
}

[[noreturn]] void refuse_required(const std::string& file, const std::string& name) {
  if (name == "KHR_texture_basisu")
    throw Error(file + ": requires KHR_texture_basisu (KTX2/Basis Universal textures), which pxf cannot decode "
                "(Debian has no KTX2 decoder); export the textures as PNG, JPEG or WebP");
  throw Error(file + ": required extension " + name + " is not supported");
}

void check_required(const json& doc, const std::string& file, const std::set<std::string>& supported) {
  const auto required = doc.find("extensionsRequired");
  if (required == doc.end() || !required->is_array()) return;
  for (const json& name : *required)
    if (name.is_string() && !supported.count(name.get<std::string>())) refuse_required(file, name.get<std::string>());
}

const json* extension(const json& object, const char* name) {
  if (!object.is_object()) return nullptr;
  const auto extensions = object.find("extensions");
  if (extensions == object.end() || !extensions->is_object()) return nullptr;
  const auto found = extensions->find(name);
  return found != extensions->end() && found->is_object() ? &*found : nullptr;
}

// Index accessors of Draco primitives that have no bufferView get the extension's one (tinygltf
// refuses an index accessor without); their indices are returned for the restore.
std::vector<int> lend_draco_index_views(json& doc) {
  std::vector<int> lent;
  json* accessors = doc.contains("accessors") && doc["accessors"].is_array() ? &doc["accessors"] : nullptr;
  if (!accessors || !doc.contains("meshes") || !doc["meshes"].is_array()) return lent;
  for (json& mesh : doc["meshes"]) {
    if (!mesh.is_object() || !mesh.contains("primitives") || !mesh["primitives"].is_array()) continue;
    for (json& primitive : mesh["primitives"]) {
      const json* draco = extension(primitive, kDraco);
      if (!draco || !primitive.contains("indices") || !primitive["indices"].is_number_unsigned()) continue;
      const size_t index = primitive["indices"].get<size_t>();
      const auto view = draco->find("bufferView");
      if (index >= accessors->size() || view == draco->end() || !view->is_number_unsigned()) continue;
      json& accessor = (*accessors)[index];
      if (!accessor.is_object() || accessor.contains("bufferView")) continue;
      accessor["bufferView"] = *view;
      lent.push_back(static_cast<int>(index));
    }
  }
  return lent;
}

// Fallback buffers of EXT_meshopt_compression: one byte instead of data that only exists compressed.
bool replace_meshopt_fallback_buffers(json& doc) {
  bool replaced = false;
  if (!doc.contains("buffers") || !doc["buffers"].is_array()) return false;
  for (json& buffer : doc["buffers"]) {
    const json* meshopt = extension(buffer, kMeshopt);
    if (!meshopt || buffer.contains("uri")) continue;
    const auto fallback = meshopt->find("fallback");
    if (fallback == meshopt->end() || *fallback != true) continue;
    buffer["byteLength"] = 1;
    buffer["uri"] = "data:application/octet-stream;base64,AA==";
    replaced = true;
  }
  return replaced;
}

// The GLB again with `text` as its JSON chunk; the other chunks as they were.
std::vector<unsigned char> replace_glb_json(const unsigned char* data, size_t size, std::string text) {
  while (text.size() % 4) text += ' ';
  uint32_t old_length = 0;
  std::memcpy(&old_length, data + 12, sizeof old_length);
  const size_t rest = 20 + static_cast<size_t>(old_length) <= size ? 20 + static_cast<size_t>(old_length) : size;
  std::vector<unsigned char> out(data, data + 20);
  out.insert(out.end(), text.begin(), text.end());
  out.insert(out.end(), data + rest, data + size);
  const uint32_t total = static_cast<uint32_t>(std::min<size_t>(out.size(), UINT32_MAX));
  const uint32_t json_length = static_cast<uint32_t>(text.size());
  std::memcpy(out.data() + 8, &total, sizeof total);
  std::memcpy(out.data() + 12, &json_length, sizeof json_length);
  return out;
}

}  // namespace

PreparedJson prepare_json(const unsigned char* data, size_t size, bool binary, const std::string& file,
                          const std::set<std::string>& supported) {
  PreparedJson prepared;
  const JsonText text = json_text(data, size, binary);
  if (!text.data || !(mentions(text.data, text.size, "extensionsRequired") || mentions(text.data, text.size, kDraco) ||
                      mentions(text.data, text.size, kMeshopt)))
    return prepared;
  json doc = json::parse(text.data, text.data + text.size, nullptr, /*allow_exceptions=*/false);
  if (!doc.is_object()) return prepared;  // tinygltf names the syntax error
  check_required(doc, file, supported);
  prepared.draco_index_accessors = lend_draco_index_views(doc);
  const bool replaced = replace_meshopt_fallback_buffers(doc);
  if (prepared.draco_index_accessors.empty() && !replaced) return prepared;
  // Invalid UTF-8 in a name would make dump() throw; tinygltf reads the replacement characters.
  std::string rewritten = doc.dump(-1, ' ', false, json::error_handler_t::replace);
  prepared.rewritten = true;
  if (binary) prepared.bytes = replace_glb_json(data, size, std::move(rewritten));
  else prepared.bytes.assign(rewritten.begin(), rewritten.end());
  return prepared;
}

void restore_draco_index_accessors(tinygltf::Model& model, const PreparedJson& prepared) {
  for (int index : prepared.draco_index_accessors)
    if (index < static_cast<int>(model.accessors.size())) model.accessors[index].bufferView = -1;
}

}  // namespace pxf::gltf
