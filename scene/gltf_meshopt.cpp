#include "scene/gltf_meshopt.h"

#include <meshoptimizer.h>
#include <tiny_gltf.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <set>
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

// A string property; `fallback` when absent. Any other type is refused by name: a number is not
// taken as the fallback (a "filter": 5 is no filter NONE).
std::string string_member(const tinygltf::Value& object, const char* key, const std::string& fallback,
                          const std::string& file, const std::string& what) {
  if (!object.Has(key)) return fallback;
  const tinygltf::Value& v = object.Get(key);
  if (v.IsString()) return v.Get<std::string>();
  std::string shown = "a non-string value";
  if (v.IsNumber()) {
    char text[64];
    std::snprintf(text, sizeof text, "%.17g", v.GetNumberAsDouble());
    shown = text;
  } else if (v.IsBool()) {
    shown = v.Get<bool>() ? "true" : "false";
  }
  throw Error(file + ": " + what + ": " + key + " " + shown + " is not a name (" +
              (std::string(key) == "filter" ? "NONE, OCTAHEDRAL, QUATERNION or EXPONENTIAL" : "ATTRIBUTES, TRIANGLES or INDICES") + ")");
}

// What the extension says about one view.
struct CompressedView {
  const unsigned char* data = nullptr;
  size_t buffer = 0, offset = 0, size = 0;
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
  view.buffer = static_cast<size_t>(buffer);
  view.offset = static_cast<size_t>(offset);
  view.size = static_cast<size_t>(length);
  view.count = static_cast<size_t>(count);
  view.stride = static_cast<size_t>(stride);
  view.mode = string_member(ext, "mode", "", file, what);
  view.filter = string_member(ext, "filter", "NONE", file, what);
  return view;
}

void check_layout(const CompressedView& view, const std::string& file, const std::string& what) {
  if (view.filter != "NONE" && view.filter != "OCTAHEDRAL" && view.filter != "QUATERNION" && view.filter != "EXPONENTIAL")
    fail(file, what, "unknown filter '" + view.filter + "' (NONE, OCTAHEDRAL, QUATERNION or EXPONENTIAL)");
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
  std::vector<unsigned char> out(view.count * view.stride);
  if (view.count > 0 && decode(view, out) != 0)
    fail(file, what, "malformed EXT_meshopt_compression data (" + view.mode + ", " + std::to_string(view.size) + " bytes)");
  apply_filter(view, out);
  return out;
}

const tinygltf::Value* compressed_extension(const tinygltf::Model& model, int v, const std::string& file) {
  if (v < 0 || v >= static_cast<int>(model.bufferViews.size())) return nullptr;
  const auto found = model.bufferViews[v].extensions.find(kExtension);
  if (found == model.bufferViews[v].extensions.end()) return nullptr;
  if (!found->second.IsObject()) fail(file, "bufferView " + std::to_string(v), std::string(kExtension) + " is not an object");
  return &found->second;
}

}  // namespace

MeshoptPlan plan_meshopt_views(const tinygltf::Model& model, const std::string& file) {
  MeshoptPlan plan;
  std::set<int> image_views, accessor_views;
  for (const tinygltf::Image& image : model.images)
    if (compressed_extension(model, image.bufferView, file)) image_views.insert(image.bufferView);
  for (const tinygltf::Accessor& accessor : model.accessors)
    for (int v : {accessor.bufferView, accessor.sparse.isSparse ? accessor.sparse.indices.bufferView : -1,
                  accessor.sparse.isSparse ? accessor.sparse.values.bufferView : -1})
      if (!image_views.count(v) && compressed_extension(model, v, file)) accessor_views.insert(v);
  for (const tinygltf::Mesh& mesh : model.meshes)  // a Draco primitive's bytes, decoded after these
    for (const tinygltf::Primitive& primitive : mesh.primitives) {
      const auto draco = primitive.extensions.find("KHR_draco_mesh_compression");
      if (draco == primitive.extensions.end() || !draco->second.IsObject()) continue;
      const int64_t v = integer_member(draco->second, "bufferView");
      if (v >= 0 && v < static_cast<int64_t>(model.bufferViews.size()) && !image_views.count(static_cast<int>(v)) &&
          compressed_extension(model, static_cast<int>(v), file))
        accessor_views.insert(static_cast<int>(v));
    }
  plan.image_views.assign(image_views.begin(), image_views.end());
  plan.accessor_views.assign(accessor_views.begin(), accessor_views.end());
  // Each used view checked on its own, then all of them against the compressed bytes they read,
  // each byte counted once however many views name it.
  std::map<size_t, std::vector<std::pair<size_t, size_t>>> ranges;  // buffer -> [begin, end)
  uint64_t views = 0;
  for (const std::vector<int>* list : {&plan.image_views, &plan.accessor_views})
    for (int v : *list) {
      const std::string what = "bufferView " + std::to_string(v);
      const CompressedView view = describe(model, *compressed_extension(model, v, file), file, what);
      check_layout(view, file, what);
      plan.decoded_bytes += static_cast<uint64_t>(view.count) * view.stride;  // each at most 64 × 4 GiB
      ranges[view.buffer].emplace_back(view.offset, view.offset + view.size);
      ++views;
    }
  uint64_t compressed = 0;
  for (auto& [buffer, list] : ranges) {
    std::sort(list.begin(), list.end());
    size_t end = 0;
    for (const auto& [b, e] : list) {
      if (e > std::max(b, end)) compressed += e - std::max(b, end);
      end = std::max(end, e);
    }
  }
  if (plan.decoded_bytes > kMaxMeshoptExpansion * compressed + 256 * views)
    throw Error(file + ": " + std::to_string(views) + " EXT_meshopt_compression bufferViews claim " +
                std::to_string(plan.decoded_bytes) + " decoded bytes from " + std::to_string(compressed) +
                " distinct compressed bytes, more than the codec can expand to (views that share compressed bytes?)");
  return plan;
}

void decode_meshopt_views(tinygltf::Model& model, const std::string& file, const std::vector<int>& views) {
  // Decoded first, installed after: a new buffer may move the compressed bytes other views read.
  std::vector<std::pair<size_t, std::vector<unsigned char>>> decoded;
  for (int v : views) {
    const tinygltf::Value* ext = compressed_extension(model, v, file);
    if (!ext) continue;
    decoded.emplace_back(v, decode_view(model, *ext, file, "bufferView " + std::to_string(v)));
  }
  for (auto& [v, bytes] : decoded) {
    tinygltf::BufferView& view = model.bufferViews[v];
    view.extensions.erase(kExtension);  // decoded: a view is decoded once
    view.buffer = static_cast<int>(model.buffers.size());
    view.byteOffset = 0;
    view.byteLength = bytes.size();
    model.buffers.emplace_back();
    model.buffers.back().data = std::move(bytes);
  }
}

}  // namespace pxf::gltf
