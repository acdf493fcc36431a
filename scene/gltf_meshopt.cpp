#include "scene/gltf_meshopt.h"

#include <meshoptimizer.h>
#include <tiny_gltf.h>

#include <vector>

#include "core/error.h"

namespace pxf::gltf {
namespace {

constexpr const char* kExtension = "EXT_meshopt_compression";

[[noreturn]] void fail(const std::string& file, const std::string& what, const std::string& problem) {
  throw Error(file + ": " + what + ": " + problem);
}

// A non-negative integer property; -1 when absent or not one.
int64_t integer_member(const tinygltf::Value& object, const char* key, int64_t fallback = -1) {
  const tinygltf::Value& v = object.Get(key);
  if (!v.IsNumber()) return fallback;
  const double d = v.GetNumberAsDouble();
  return d >= 0 && d <= 9007199254740992.0 && d == static_cast<double>(static_cast<int64_t>(d)) ? static_cast<int64_t>(d) : -1;
}

std::string string_member(const tinygltf::Value& object, const char* key, const std::string& fallback) {
  const tinygltf::Value& v = object.Get(key);
  return v.IsString() ? v.Get<std::string>() : fallback;
}

// What the extension says about one view.
struct CompressedView {
  const unsigned char* data = nullptr;
  size_t size = 0;
  size_t count = 0, stride = 0;
  std::string mode, filter;
};

CompressedView describe(const tinygltf::Model& model, const tinygltf::Value& ext, const std::string& file, const std::string& what) {
  CompressedView view;
  const int64_t buffer = integer_member(ext, "buffer"), offset = integer_member(ext, "byteOffset", 0),
                length = integer_member(ext, "byteLength"), count = integer_member(ext, "count"),
                stride = integer_member(ext, "byteStride");
  if (buffer < 0 || buffer >= static_cast<int64_t>(model.buffers.size())) fail(file, what, "compressed buffer out of range");
  const std::vector<unsigned char>& bytes = model.buffers[buffer].data;
  if (offset < 0 || length < 0 || static_cast<uint64_t>(offset) > bytes.size() ||
      static_cast<uint64_t>(length) > bytes.size() - static_cast<uint64_t>(offset))
    fail(file, what, "compressed bytes exceed buffer " + std::to_string(buffer) + " (" + std::to_string(bytes.size()) + " bytes)");
  if (count < 0 || stride <= 0 || stride > 256) fail(file, what, "count or byteStride missing or out of range");
  view.data = bytes.data() + offset;
  view.size = static_cast<size_t>(length);
  view.count = static_cast<size_t>(count);
  view.stride = static_cast<size_t>(stride);
  view.mode = string_member(ext, "mode", "");
  view.filter = string_member(ext, "filter", "NONE");
  return view;
}

void check_layout(const CompressedView& view, const std::string& file, const std::string& what) {
  if (view.mode == "ATTRIBUTES") {
    if (view.stride % 4 != 0) fail(file, what, "ATTRIBUTES byteStride " + std::to_string(view.stride) + " is not a multiple of 4");
  } else if (view.mode == "TRIANGLES" || view.mode == "INDICES") {
    if (view.stride != 2 && view.stride != 4) fail(file, what, view.mode + " byteStride must be 2 or 4");
    if (view.mode == "TRIANGLES" && view.count % 3 != 0) fail(file, what, "TRIANGLES count is not a multiple of 3");
    if (view.filter != "NONE") fail(file, what, "filter " + view.filter + " applies to ATTRIBUTES only");
  } else {
    fail(file, what, "unknown mode '" + view.mode + "' (ATTRIBUTES, TRIANGLES or INDICES)");
  }
  const bool filter_fits = view.filter == "NONE" || (view.filter == "OCTAHEDRAL" && (view.stride == 4 || view.stride == 8)) ||
                           (view.filter == "QUATERNION" && view.stride == 8) || (view.filter == "EXPONENTIAL" && view.stride % 4 == 0);
  if (!filter_fits) fail(file, what, "filter '" + view.filter + "' does not fit byteStride " + std::to_string(view.stride));
  if (view.count > (kMaxMeshoptExpansion * view.size + 256) / view.stride)
    fail(file, what, "claims " + std::to_string(view.count) + " elements of " + std::to_string(view.stride) + " bytes from " +
                         std::to_string(view.size) + " compressed bytes, more than the codec can expand to");
}

int decode(const CompressedView& view, std::vector<unsigned char>& out) {
  if (view.mode == "ATTRIBUTES") return meshopt_decodeVertexBuffer(out.data(), view.count, view.stride, view.data, view.size);
  if (view.mode == "TRIANGLES") return meshopt_decodeIndexBuffer(out.data(), view.count, view.stride, view.data, view.size);
  return meshopt_decodeIndexSequence(out.data(), view.count, view.stride, view.data, view.size);
}

void apply_filter(const CompressedView& view, std::vector<unsigned char>& out) {
  if (view.filter == "OCTAHEDRAL") meshopt_decodeFilterOct(out.data(), view.count, view.stride);
  else if (view.filter == "QUATERNION") meshopt_decodeFilterQuat(out.data(), view.count, view.stride);
  else if (view.filter == "EXPONENTIAL") meshopt_decodeFilterExp(out.data(), view.count, view.stride);
}

std::vector<unsigned char> decode_view(const tinygltf::Model& model, const tinygltf::Value& ext, const std::string& file,
                                       const std::string& what) {
  const CompressedView view = describe(model, ext, file, what);
  check_layout(view, file, what);
  if (view.filter != "NONE" && view.filter != "OCTAHEDRAL" && view.filter != "QUATERNION" && view.filter != "EXPONENTIAL")
    fail(file, what, "unknown filter '" + view.filter + "'");
  std::vector<unsigned char> out(view.count * view.stride);
  if (view.count > 0 && decode(view, out) != 0)
    fail(file, what, "malformed EXT_meshopt_compression data (" + view.mode + ", " + std::to_string(view.size) + " bytes)");
  apply_filter(view, out);
  return out;
}

}  // namespace

void decode_meshopt_views(tinygltf::Model& model, const std::string& file) {
  // Decoded first, installed after: a new buffer may move the compressed bytes other views read.
  std::vector<std::pair<size_t, std::vector<unsigned char>>> decoded;
  for (size_t v = 0; v < model.bufferViews.size(); ++v) {
    const auto found = model.bufferViews[v].extensions.find(kExtension);
    if (found == model.bufferViews[v].extensions.end()) continue;
    const std::string what = "bufferView " + std::to_string(v);
    if (!found->second.IsObject()) fail(file, what, std::string(kExtension) + " is not an object");
    decoded.emplace_back(v, decode_view(model, found->second, file, what));
  }
  for (auto& [v, bytes] : decoded) {
    tinygltf::BufferView& view = model.bufferViews[v];
    view.buffer = static_cast<int>(model.buffers.size());
    view.byteOffset = 0;
    view.byteLength = bytes.size();
    model.buffers.emplace_back();
    model.buffers.back().data = std::move(bytes);
  }
}

}  // namespace pxf::gltf
