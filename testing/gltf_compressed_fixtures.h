// Small compressed glTF files and their uncompressed twins, written with the libraries' own
// encoders (libdraco, libwebp, meshoptimizer) so that no binary file is committed: used by
// scene/gltf_compression_test.cpp and by fuzz/make_compressed_gltf.cpp (the fuzz seeds).
// Header-only, in pxf_testing: only test and seed programs include it.
#pragma once
#include <draco/compression/encode.h>
#include <draco/mesh/mesh.h>
#include <meshoptimizer.h>
#include <stb/stb_image_write.h>  // libstb.so has the implementation
#include <webp/encode.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "testing/glb_test_util.h"

namespace pxf::gltf_fixtures {

using json = nlohmann::json;
using Bytes = std::vector<unsigned char>;

constexpr int kFloat = 5126, kUnsignedInt = 5125, kShort = 5122, kByte = 5120;

// A GLB under construction: JSON and one BIN chunk.
struct Glb {
  json doc = {{"asset", {{"version", "2.0"}}}};
  Bytes bin;

  int view(const void* data, size_t size, size_t stride = 0) {
    while (bin.size() % 4) bin.push_back(0);
    json v = {{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", size}};
    if (stride) v["byteStride"] = stride;
    const auto* p = static_cast<const unsigned char*>(data);
    bin.insert(bin.end(), p, p + size);
    doc["bufferViews"].push_back(v);
    return static_cast<int>(doc["bufferViews"].size()) - 1;
  }
  int accessor(int view_index, int component_type, size_t count, const std::string& type, bool normalized = false) {
    json a = {{"componentType", component_type}, {"count", count}, {"type", type}};
    if (view_index >= 0) a["bufferView"] = view_index;
    if (normalized) a["normalized"] = true;
    doc["accessors"].push_back(a);
    return static_cast<int>(doc["accessors"].size()) - 1;
  }
  void require(const std::string& extension) {
    doc["extensionsUsed"].push_back(extension);
    doc["extensionsRequired"].push_back(extension);
  }
  // One node with mesh 0 (and `node_extra` merged into it) as the scene.
  void single_node_scene(const json& node_extra = json::object()) {
    json node = {{"mesh", 0}};
    node.update(node_extra);
    doc["nodes"] = json::array({node});
    doc["scenes"] = json::array({{{"nodes", {0}}}});
    doc["scene"] = 0;
  }
  Bytes bytes() const {
    json d = doc;
    Bytes payload = bin;
    while (payload.size() % 4) payload.push_back(0);
    if (!payload.empty()) {
      if (!d.contains("buffers")) d["buffers"] = json::array();
      d["buffers"].insert(d["buffers"].begin(), json{{"byteLength", bin.size()}});
    }
    std::string text = d.dump();
    while (text.size() % 4) text += ' ';
    return test::glb_container(text, payload);  // Bytes is std::vector<uint8_t>
  }
};

// A wavy grid of side x side quads with normals and UVs: 2 side^2 triangles.
struct GridMesh {
  std::vector<float> positions, normals, uvs;  // 3, 3, 2 per vertex
  std::vector<uint32_t> indices;
  size_t vertex_count() const { return positions.size() / 3; }
};

inline GridMesh make_grid(int side) {
  GridMesh g;
  const int n = side + 1;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const float u = static_cast<float>(i) / side, v = static_cast<float>(j) / side;
      const float z = 0.1f * std::sin(6.0f * u) * std::cos(5.0f * v);
      const float dzdu = 0.6f * std::cos(6.0f * u) * std::cos(5.0f * v), dzdv = -0.5f * std::sin(6.0f * u) * std::sin(5.0f * v);
      const float length = std::sqrt(dzdu * dzdu + dzdv * dzdv + 1.0f);
      g.positions.insert(g.positions.end(), {u - 0.5f, v - 0.5f, z});
      g.normals.insert(g.normals.end(), {-dzdu / length, -dzdv / length, 1.0f / length});
      g.uvs.insert(g.uvs.end(), {u, 1.0f - v});
    }
  for (int j = 0; j < side; ++j)
    for (int i = 0; i < side; ++i) {
      const uint32_t a = j * n + i, b = a + 1, c = a + n + 1, d = a + n;
      g.indices.insert(g.indices.end(), {a, b, c, a, c, d});
    }
  return g;
}

// The grid as a plain GLB: float attributes, uint32 indices.
inline Glb plain_grid_glb(const GridMesh& g) {
  Glb glb;
  const size_t n = g.vertex_count();
  json attributes = {{"POSITION", glb.accessor(glb.view(g.positions.data(), g.positions.size() * 4), kFloat, n, "VEC3")},
                     {"NORMAL", glb.accessor(glb.view(g.normals.data(), g.normals.size() * 4), kFloat, n, "VEC3")},
                     {"TEXCOORD_0", glb.accessor(glb.view(g.uvs.data(), g.uvs.size() * 4), kFloat, n, "VEC2")}};
  const int indices = glb.accessor(glb.view(g.indices.data(), g.indices.size() * 4), kUnsignedInt, g.indices.size(), "SCALAR");
  glb.doc["meshes"] = json::array({{{"primitives", json::array({{{"attributes", attributes}, {"indices", indices}}})}}});
  glb.single_node_scene();
  return glb;
}

// ------------------------------------------------------------------------------------- Draco

// Blender's default Draco quantization (bits): what most Draco files in the wild carry.
struct DracoQuantization {
  int position = 14, normal = 10, uv = 12;
};

// The grid Draco-encoded with edgebreaker: without quantization by default (lossless: the twin's
// values exactly), or quantized as `quantization` says. The accessors keep their counts and types
// and have no bufferView, as exporters write them.
inline Glb draco_grid_glb(const GridMesh& g, const DracoQuantization* quantization = nullptr) {
  draco::Mesh mesh;
  const size_t n = g.vertex_count();
  mesh.set_num_points(static_cast<uint32_t>(n));
  auto add = [&](draco::GeometryAttribute::Type type, const std::vector<float>& values, int components) {
    draco::GeometryAttribute attribute;
    attribute.Init(type, nullptr, static_cast<int8_t>(components), draco::DT_FLOAT32, false, sizeof(float) * components, 0);
    const int id = mesh.AddAttribute(attribute, true, static_cast<uint32_t>(n));
    for (size_t i = 0; i < n; ++i)
      mesh.attribute(id)->SetAttributeValue(draco::AttributeValueIndex(static_cast<uint32_t>(i)), &values[i * components]);
    return mesh.attribute(id)->unique_id();
  };
  const uint32_t position = add(draco::GeometryAttribute::POSITION, g.positions, 3);
  const uint32_t normal = add(draco::GeometryAttribute::NORMAL, g.normals, 3);
  const uint32_t uv = add(draco::GeometryAttribute::TEX_COORD, g.uvs, 2);
  for (size_t t = 0; t < g.indices.size(); t += 3)
    mesh.AddFace({draco::PointIndex(g.indices[t]), draco::PointIndex(g.indices[t + 1]), draco::PointIndex(g.indices[t + 2])});
  draco::Encoder encoder;
  encoder.SetEncodingMethod(draco::MESH_EDGEBREAKER_ENCODING);
  if (quantization) {
    encoder.SetAttributeQuantization(draco::GeometryAttribute::POSITION, quantization->position);
    encoder.SetAttributeQuantization(draco::GeometryAttribute::NORMAL, quantization->normal);
    encoder.SetAttributeQuantization(draco::GeometryAttribute::TEX_COORD, quantization->uv);
  }
  draco::EncoderBuffer encoded;
  const draco::Status status = encoder.EncodeMeshToBuffer(mesh, &encoded);
  if (!status.ok()) throw std::runtime_error("Draco encoding failed: " + status.error_msg_string());

  Glb glb;
  const int view = glb.view(encoded.data(), encoded.size());
  json attributes = {{"POSITION", glb.accessor(-1, kFloat, n, "VEC3")}, {"NORMAL", glb.accessor(-1, kFloat, n, "VEC3")},
                     {"TEXCOORD_0", glb.accessor(-1, kFloat, n, "VEC2")}};
  const int indices = glb.accessor(-1, kUnsignedInt, g.indices.size(), "SCALAR");
  json draco_ext = {{"bufferView", view}, {"attributes", {{"POSITION", position}, {"NORMAL", normal}, {"TEXCOORD_0", uv}}}};
  json primitive = {{"attributes", attributes}, {"indices", indices},
                    {"extensions", {{"KHR_draco_mesh_compression", draco_ext}}}};
  glb.doc["meshes"] = json::array({{{"primitives", json::array({primitive})}}});
  glb.require("KHR_draco_mesh_compression");
  glb.single_node_scene();
  return glb;
}

// ------------------------------------------------------------------------------------- meshopt

// A meshopt file and its uncompressed twin: the same bufferViews, decoded.
struct MeshoptPair {
  Glb compressed, plain;
};

// The views of a meshopt file as gltfpack writes them: the compressed bytes in buffer 0 (the BIN
// chunk, which Glb::bytes puts first), the views in a fallback buffer 1 that has no data.
class MeshoptWriter {
 public:
  MeshoptPair files;

  MeshoptWriter() {
    files.compressed.doc["buffers"] = json::array(
        {{{"byteLength", 0}, {"extensions", {{"EXT_meshopt_compression", {{"fallback", true}}}}}}});
    files.compressed.require("EXT_meshopt_compression");
  }
  // `decoded`: the view's bytes as a decoder returns them (after the filter).
  int attributes(const Bytes& decoded, size_t stride, const char* filter = "NONE", const Bytes* encoded_input = nullptr) {
    const Bytes& input = encoded_input ? *encoded_input : decoded;
    const size_t count = decoded.size() / stride;
    Bytes encoded(meshopt_encodeVertexBufferBound(count, stride));
    encoded.resize(meshopt_encodeVertexBuffer(encoded.data(), encoded.size(), input.data(), count, stride));
    return add(decoded, encoded, stride, count, "ATTRIBUTES", filter, true);
  }
  int triangles(const std::vector<uint32_t>& indices, size_t vertex_count) {
    Bytes encoded(meshopt_encodeIndexBufferBound(indices.size(), vertex_count));
    encoded.resize(meshopt_encodeIndexBuffer(encoded.data(), encoded.size(), indices.data(), indices.size()));
    return add(as_bytes(indices), encoded, 4, indices.size(), "TRIANGLES", "NONE", false);
  }
  int index_sequence(const std::vector<uint32_t>& indices, size_t vertex_count) {
    Bytes encoded(meshopt_encodeIndexSequenceBound(indices.size(), vertex_count));
    encoded.resize(meshopt_encodeIndexSequence(encoded.data(), encoded.size(), indices.data(), indices.size()));
    return add(as_bytes(indices), encoded, 4, indices.size(), "INDICES", "NONE", false);
  }
  int accessor(int view, int component_type, size_t count, const std::string& type, bool normalized = false) {
    files.plain.accessor(view, component_type, count, type, normalized);
    return files.compressed.accessor(view, component_type, count, type, normalized);
  }
  void set(const std::string& key, const json& value) {
    files.plain.doc[key] = value;
    files.compressed.doc[key] = value;
  }
  template <typename T>
  static Bytes as_bytes(const std::vector<T>& values) {
    const auto* p = reinterpret_cast<const unsigned char*>(values.data());
    return Bytes(p, p + values.size() * sizeof(T));
  }

 private:
  int add(const Bytes& decoded, const Bytes& encoded, size_t stride, size_t count, const char* mode, const char* filter,
          bool vertex_data) {
    const int plain_view = files.plain.view(decoded.data(), decoded.size(), vertex_data ? stride : 0);
    Glb& c = files.compressed;
    while (c.bin.size() % 4) c.bin.push_back(0);
    json ext = {{"buffer", 0}, {"byteOffset", c.bin.size()}, {"byteLength", encoded.size()}, {"byteStride", stride},
                {"count", count}, {"mode", mode}};
    if (std::string(filter) != "NONE") ext["filter"] = filter;
    c.bin.insert(c.bin.end(), encoded.begin(), encoded.end());
    json view = {{"buffer", 1}, {"byteOffset", fallback_size_}, {"byteLength", decoded.size()},
                 {"extensions", {{"EXT_meshopt_compression", ext}}}};
    if (vertex_data) view["byteStride"] = stride;
    fallback_size_ += (decoded.size() + 3) / 4 * 4;
    c.doc["buffers"][0]["byteLength"] = fallback_size_;
    c.doc["bufferViews"].push_back(view);
    if (static_cast<int>(c.doc["bufferViews"].size()) - 1 != plain_view) throw std::logic_error("view numbering");
    return plain_view;
  }
  size_t fallback_size_ = 0;
};

// The grid with meshopt: positions EXPONENTIAL-filtered (float), normals OCTAHEDRAL (snorm8),
// UVs unfiltered, indices as TRIANGLES; and a second primitive whose indices are an INDICES
// sequence. Node 0 instances the mesh `instances` times (EXT_mesh_gpu_instancing) with rotations
// QUATERNION-filtered (snorm16) when instances > 0.
inline MeshoptPair meshopt_grid_glbs(const GridMesh& g, int instances = 0) {
  MeshoptWriter w;
  const size_t n = g.vertex_count();
  Bytes positions(n * 12), normals(n * 4);
  meshopt_encodeFilterExp(positions.data(), n, 12, 15, g.positions.data());
  const Bytes positions_encoded = positions;
  meshopt_decodeFilterExp(positions.data(), n, 12);
  std::vector<float> normals4;
  for (size_t i = 0; i < n; ++i) normals4.insert(normals4.end(), {g.normals[3 * i], g.normals[3 * i + 1], g.normals[3 * i + 2], 0.0f});
  meshopt_encodeFilterOct(normals.data(), n, 4, 8, normals4.data());
  const Bytes normals_encoded = normals;
  meshopt_decodeFilterOct(normals.data(), n, 4);
  json attributes = {
      {"POSITION", w.accessor(w.attributes(positions, 12, "EXPONENTIAL", &positions_encoded), kFloat, n, "VEC3")},
      {"NORMAL", w.accessor(w.attributes(normals, 4, "OCTAHEDRAL", &normals_encoded), kByte, n, "VEC3", true)},
      {"TEXCOORD_0", w.accessor(w.attributes(MeshoptWriter::as_bytes(g.uvs), 8), kFloat, n, "VEC2")}};
  const int triangles = w.accessor(w.triangles(g.indices, n), kUnsignedInt, g.indices.size(), "SCALAR");
  const std::vector<uint32_t> first_half(g.indices.begin(), g.indices.begin() + g.indices.size() / 6 * 3);
  const int sequence = w.accessor(w.index_sequence(first_half, n), kUnsignedInt, first_half.size(), "SCALAR");
  w.set("meshes", json::array({{{"primitives", json::array({{{"attributes", attributes}, {"indices", triangles}},
                                                             {{"attributes", attributes}, {"indices", sequence}}})}}}));
  json node_extra = json::object();
  if (instances > 0) {
    std::vector<float> translations, quaternions, scales;
    for (int i = 0; i < instances; ++i) {
      const float angle = 0.7f * i;
      translations.insert(translations.end(), {1.5f * i, 0.25f * i, -0.5f * i});
      quaternions.insert(quaternions.end(), {0.0f, std::sin(angle / 2), 0.0f, std::cos(angle / 2)});
      scales.insert(scales.end(), {1.0f + 0.5f * i, 1.0f, 0.5f + 0.25f * i});
    }
    Bytes rotations(instances * 8);
    meshopt_encodeFilterQuat(rotations.data(), instances, 8, 12, quaternions.data());
    const Bytes rotations_encoded = rotations;
    meshopt_decodeFilterQuat(rotations.data(), instances, 8);
    node_extra["extensions"] = {{"EXT_mesh_gpu_instancing", {{"attributes", {
        {"TRANSLATION", w.accessor(w.attributes(MeshoptWriter::as_bytes(translations), 12), kFloat, instances, "VEC3")},
        {"ROTATION", w.accessor(w.attributes(rotations, 8, "QUATERNION", &rotations_encoded), kShort, instances, "VEC4", true)},
        {"SCALE", w.accessor(w.attributes(MeshoptWriter::as_bytes(scales), 12), kFloat, instances, "VEC3")}}}}}};
    w.files.compressed.doc["extensionsUsed"].push_back("EXT_mesh_gpu_instancing");
    w.files.plain.doc["extensionsUsed"].push_back("EXT_mesh_gpu_instancing");
  }
  w.files.compressed.single_node_scene(node_extra);
  w.files.plain.single_node_scene(node_extra);
  return w.files;
}

// ------------------------------------------------------------------------------------- WebP

// An RGBA test pattern, every alpha above 0 (lossless WebP keeps the RGB of visible texels only).
inline Bytes rgba_pattern(int width, int height) {
  Bytes rgba(static_cast<size_t>(width) * height * 4);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      unsigned char* p = &rgba[(static_cast<size_t>(y) * width + x) * 4];
      p[0] = static_cast<unsigned char>(37 * x + 11 * y);
      p[1] = static_cast<unsigned char>(255 - 29 * x);
      p[2] = static_cast<unsigned char>(53 * y + 7);
      p[3] = static_cast<unsigned char>(128 + 17 * (x + y) % 128);
    }
  return rgba;
}

inline Bytes encode_webp_lossless(const Bytes& rgba, int width, int height) {
  uint8_t* out = nullptr;
  const size_t size = WebPEncodeLosslessRGBA(rgba.data(), width, height, width * 4, &out);
  if (size == 0) throw std::runtime_error("WebP encoding failed");
  Bytes webp(out, out + size);
  WebPFree(out);
  return webp;
}

inline Bytes encode_png(const Bytes& rgba, int width, int height) {
  Bytes out;
  auto append = [](void* context, void* data, int size) {
    const auto* bytes = static_cast<const unsigned char*>(data);
    static_cast<Bytes*>(context)->insert(static_cast<Bytes*>(context)->end(), bytes, bytes + size);
  };
  if (!stbi_write_png_to_func(append, &out, width, height, 4, rgba.data(), width * 4))
    throw std::runtime_error("PNG encoding failed");
  return out;
}

// A quad whose base color texture is texture 0. Its image sources are given as (mime type, bytes);
// `texture` says which image is the source and which the extensions name.
inline Glb textured_quad_glb(const std::vector<std::pair<std::string, Bytes>>& images, const json& texture) {
  Glb glb;
  const std::vector<float> positions = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}, uvs = {0, 1, 1, 1, 1, 0, 0, 0};
  const std::vector<uint32_t> indices = {0, 1, 2, 0, 2, 3};
  json attributes = {{"POSITION", glb.accessor(glb.view(positions.data(), 48), kFloat, 4, "VEC3")},
                     {"TEXCOORD_0", glb.accessor(glb.view(uvs.data(), 32), kFloat, 4, "VEC2")}};
  const int index_accessor = glb.accessor(glb.view(indices.data(), 24), kUnsignedInt, 6, "SCALAR");
  for (const auto& [mime, bytes] : images)
    glb.doc["images"].push_back({{"bufferView", glb.view(bytes.data(), bytes.size())}, {"mimeType", mime}});
  glb.doc["textures"] = json::array({texture});
  glb.doc["materials"] = json::array({{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}});
  glb.doc["meshes"] = json::array(
      {{{"primitives", json::array({{{"attributes", attributes}, {"indices", index_accessor}, {"material", 0}}})}}});
  glb.single_node_scene();
  return glb;
}

}  // namespace pxf::gltf_fixtures
