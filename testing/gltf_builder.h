// Writers of the small glTF fixtures that the loader's and the tracer's tests build in code, so
// that every feature and every bad input has its own minimal, readable file: base64 data URIs, a
// minimal PNG encoder and a glTF document with one binary buffer, written as .gltf or .glb.
#pragma once
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>
#include <nlohmann/json.hpp>

#include "testing/glb_test_util.h"

namespace pxf::test {

// An empty folder for the current test's fixture files: <gtest's TempDir>/<prefix><test name>.
inline std::string fixture_dir(const std::string& prefix) {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) / (prefix + info->name());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

inline std::string base64(const std::vector<uint8_t>& data) {
  static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  size_t i = 0;
  for (; i + 2 < data.size(); i += 3) {
    uint32_t v = (data[i] << 16) | (data[i + 1] << 8) | data[i + 2];
    for (int s = 18; s >= 0; s -= 6) out += table[(v >> s) & 63];
  }
  if (i + 1 == data.size()) {
    uint32_t v = data[i] << 16;
    out += table[(v >> 18) & 63];
    out += table[(v >> 12) & 63];
    out += "==";
  } else if (i + 2 == data.size()) {
    uint32_t v = (data[i] << 16) | (data[i + 1] << 8);
    out += table[(v >> 18) & 63];
    out += table[(v >> 12) & 63];
    out += table[(v >> 6) & 63];
    out += '=';
  }
  return out;
}

inline uint32_t crc32(const uint8_t* p, size_t n, uint32_t crc = 0) {
  crc = ~crc;
  for (size_t i = 0; i < n; ++i) {
    crc ^= p[i];
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

inline void put_be32(std::vector<uint8_t>& out, uint32_t v) {
  for (int s = 24; s >= 0; s -= 8) out.push_back(static_cast<uint8_t>(v >> s));
}

// Minimal PNG encoder (stored deflate blocks), 8 or 16 bits, 1-4 channels; samples in [0, 2^bits).
inline std::vector<uint8_t> encode_png(int w, int h, int channels, int bits, const std::vector<uint32_t>& samples) {
  std::vector<uint8_t> raw;
  for (int y = 0; y < h; ++y) {
    raw.push_back(0);  // filter: none
    for (int x = 0; x < w * channels; ++x) {
      uint32_t s = samples[static_cast<size_t>(y) * w * channels + x];
      if (bits == 16) raw.push_back(static_cast<uint8_t>(s >> 8));
      raw.push_back(static_cast<uint8_t>(s));
    }
  }
  std::vector<uint8_t> z = {0x78, 0x01};
  uint32_t a = 1, b = 0;
  for (uint8_t c : raw) {
    a = (a + c) % 65521;
    b = (b + a) % 65521;
  }
  for (size_t off = 0; off < raw.size() || off == 0; off += 65535) {
    size_t len = std::min<size_t>(65535, raw.size() - off);
    z.push_back(off + len >= raw.size() ? 1 : 0);
    z.push_back(len & 0xff);
    z.push_back(len >> 8);
    z.push_back(~len & 0xff);
    z.push_back((~len >> 8) & 0xff);
    z.insert(z.end(), raw.begin() + off, raw.begin() + off + len);
    if (raw.empty()) break;
  }
  put_be32(z, (b << 16) | a);
  std::vector<uint8_t> png = {0x89, 'P', 'N', 'G', 0x0d, 0x0a, 0x1a, 0x0a};
  auto chunk = [&](const char* type, const std::vector<uint8_t>& data) {
    put_be32(png, static_cast<uint32_t>(data.size()));
    std::vector<uint8_t> body(type, type + 4);
    body.insert(body.end(), data.begin(), data.end());
    png.insert(png.end(), body.begin(), body.end());
    put_be32(png, crc32(body.data(), body.size()));
  };
  static const uint8_t color_type[] = {0, 0, 4, 2, 6};
  std::vector<uint8_t> ihdr;
  put_be32(ihdr, w);
  put_be32(ihdr, h);
  ihdr.insert(ihdr.end(), {static_cast<uint8_t>(bits), color_type[channels], 0, 0, 0});
  chunk("IHDR", ihdr);
  chunk("IDAT", z);
  chunk("IEND", {});
  return png;
}

inline void write_bytes(const std::string& path, const std::vector<uint8_t>& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

// Builds a glTF document with one binary buffer.
class GltfBuilder {
 public:
  using json = nlohmann::json;
  json doc = {{"asset", {{"version", "2.0"}}}};
  std::vector<uint8_t> bin;

  int view(const void* data, size_t bytes) {
    while (bin.size() % 4) bin.push_back(0);
    size_t offset = bin.size();
    const auto* p = static_cast<const uint8_t*>(data);
    bin.insert(bin.end(), p, p + bytes);
    doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", offset}, {"byteLength", bytes}});
    return static_cast<int>(doc["bufferViews"].size()) - 1;
  }
  int accessor(int view_index, int component_type, size_t count, const std::string& type, bool normalized = false) {
    json a = {{"bufferView", view_index}, {"componentType", component_type}, {"count", count}, {"type", type}};
    if (normalized) a["normalized"] = true;
    doc["accessors"].push_back(a);
    return static_cast<int>(doc["accessors"].size()) - 1;
  }
  int floats(const std::vector<float>& v, const std::string& type) {
    int n = type == "SCALAR" ? 1 : type == "VEC2" ? 2 : type == "VEC3" ? 3 : 4;
    return accessor(view(v.data(), v.size() * 4), 5126, v.size() / n, type);
  }
  int indices(const std::vector<uint32_t>& v) { return accessor(view(v.data(), v.size() * 4), 5125, v.size(), "SCALAR"); }
  int image(const std::vector<uint8_t>& png) {  // embedded as a data URI
    doc["images"].push_back({{"uri", "data:image/png;base64," + base64(png)}});
    return static_cast<int>(doc["images"].size()) - 1;
  }
  int texture(int image_index, json extra = json::object()) {
    json t = {{"source", image_index}};
    t.update(extra);
    doc["textures"].push_back(t);
    return static_cast<int>(doc["textures"].size()) - 1;
  }
  int material(const json& m) {
    doc["materials"].push_back(m);
    return static_cast<int>(doc["materials"].size()) - 1;
  }
  int mesh(const json& primitive) {
    doc["meshes"].push_back({{"primitives", json::array({primitive})}});
    return static_cast<int>(doc["meshes"].size()) - 1;
  }
  int node(const json& n) {
    doc["nodes"].push_back(n);
    return static_cast<int>(doc["nodes"].size()) - 1;
  }
  void scene(const std::vector<int>& roots, const json& extras = nullptr) {
    json s = {{"nodes", roots}};
    if (!extras.is_null()) s["extras"] = extras;
    doc["scenes"] = json::array({s});
    doc["scene"] = 0;
  }
  // A unit quad in the XY plane facing +Z; glTF UVs (v runs down).
  json quad_primitive(int material_index = -1, bool with_uv = true) {
    json attributes = {{"POSITION", floats({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}, "VEC3")}};
    if (with_uv) attributes["TEXCOORD_0"] = floats({0, 1, 1, 1, 1, 0, 0, 0}, "VEC2");
    json p = {{"attributes", attributes}, {"indices", indices({0, 1, 2, 0, 2, 3})}};
    if (material_index >= 0) p["material"] = material_index;
    return p;
  }
  void add_quad_scene(int material_index = -1) { scene({node({{"mesh", mesh(quad_primitive(material_index))}})}); }

  std::string write_gltf(const std::string& path) {
    json d = doc;
    if (!bin.empty()) d["buffers"] = json::array({{{"byteLength", bin.size()}, {"uri", "data:application/octet-stream;base64," + base64(bin)}}});
    std::ofstream(path) << d.dump(1);
    return path;
  }
  std::string write_glb(const std::string& path) {
    json d = doc;
    std::vector<uint8_t> payload = bin;
    while (payload.size() % 4) payload.push_back(0);
    if (!payload.empty()) d["buffers"] = json::array({{{"byteLength", bin.size()}}});
    std::string text = d.dump();
    while (text.size() % 4) text += ' ';
    const std::vector<uint8_t> out = test::glb_container(text, payload);
    write_bytes(path, out);
    return path;
  }
};

}  // namespace pxf::test
