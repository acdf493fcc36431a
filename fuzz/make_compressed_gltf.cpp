// Writes compressed glTF files with the libraries' own encoders (testing/gltf_compressed_fixtures.h),
// which fuzz/make_seeds.py (standard library only) cannot:
//   make_compressed_gltf seeds DIR
//       the gltf_scene fuzz seeds of compressed glTF: Draco, meshopt (every mode and filter, instancing),
//       WebP and KTX2 textures, each valid and malformed (fuzz/corpus/gltf_scene/compressed_*);
//   make_compressed_gltf draco-pair SIDE DIR
//       DIR/grid_plain.glb, DIR/grid_draco.glb and DIR/grid_draco_quantized.glb, a grid of 2 SIDE^2
//       triangles uncompressed, Draco-compressed losslessly and with Blender's default quantization
//       (SIDE 152: 46,208 triangles, DamagedHelmet's count), for load-time and memory measurements
//       (docs/gltf-extensions.md);
//   make_compressed_gltf meshopt-bombs DIR
//       meshopt files of about 1 MB whose views share their compressed bytes (used by accessors or
//       not) or expand 64-fold, for the memory measurements of docs/robustness.md;
//   make_compressed_gltf draco-glb IN.glb OUT.glb
//       IN with every primitive (float attributes, uint32 or uint16 indices, triangles)
//       Draco-compressed with Blender's default quantization and its uncompressed geometry dropped:
//       pxf_helmet_like's GLB, compressed as an exporter would.
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>

#include "testing/gltf_compressed_fixtures.h"

namespace {

using namespace pxf::gltf_fixtures;

void write(const std::string& path, const Bytes& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  if (!out) throw std::runtime_error("cannot write " + path);
}

// Flips every byte of `glb`'s BIN from `from` (a fraction of the BIN) on: malformed compressed data.
Bytes corrupted(Glb glb, double from) {
  for (size_t i = static_cast<size_t>(from * glb.bin.size()); i < glb.bin.size(); ++i) glb.bin[i] ^= 0xa5;
  return glb.bytes();
}

// `views` EXT_meshopt_compression views that all name one compressed block of `count` zero
// vertices of 12 bytes (the codec's best case, about 64-fold); with `used` each has a POSITION
// accessor and a mesh of one primitive per view draws them (non-indexed, all degenerate), else no
// accessor names any of them.
Glb meshopt_shared_views(size_t count, int views, bool used) {
  const size_t stride = 12;
  const Bytes zeros(count * stride, 0);
  Bytes encoded(meshopt_encodeVertexBufferBound(count, stride));
  encoded.resize(meshopt_encodeVertexBuffer(encoded.data(), encoded.size(), zeros.data(), count, stride));
  Glb glb;
  glb.bin = encoded;  // buffer 0 (Glb::bytes puts the BIN first); buffer 1 the empty fallback
  glb.doc["buffers"] = json::array({{{"byteLength", count * stride}, {"extensions", {{"EXT_meshopt_compression", {{"fallback", true}}}}}}});
  glb.require("EXT_meshopt_compression");
  json primitives = json::array();
  for (int v = 0; v < views; ++v) {
    json ext = {{"buffer", 0}, {"byteOffset", 0}, {"byteLength", encoded.size()}, {"byteStride", stride},
                {"count", count}, {"mode", "ATTRIBUTES"}};
    glb.doc["bufferViews"].push_back({{"buffer", 1}, {"byteOffset", 0}, {"byteLength", count * stride},
                                      {"byteStride", stride}, {"extensions", {{"EXT_meshopt_compression", ext}}}});
    if (!used) continue;  // the views alone: nothing names them
    const int accessor = glb.accessor(v, 5126, count - count % 3, "VEC3");
    glb.doc["accessors"][accessor]["min"] = {0, 0, 0};
    glb.doc["accessors"][accessor]["max"] = {0, 0, 0};
    primitives.push_back({{"attributes", {{"POSITION", accessor}}}});
  }
  if (used) {
    glb.doc["meshes"] = json::array({{{"primitives", primitives}}});
    glb.single_node_scene();
  }
  return glb;
}

// Files for the memory measurements: about 1 MB each.
void write_meshopt_bombs(const std::string& dir) {
  const auto report = [&](const std::string& name, const Glb& glb) {
    const Bytes bytes = glb.bytes();
    write(dir + "/" + name, bytes);
    std::printf("wrote %s/%s (%zu bytes)\n", dir.c_str(), name.c_str(), bytes.size());
  };
  // A decompression bomb: 4,000 views of one 16 KB block (64,000 zero vertices) each.
  report("shared_unused.glb", meshopt_shared_views(87000, 4000, false));
  report("shared_used.glb", meshopt_shared_views(87000, 4000, true));
  // One view, expanded about 64-fold: 1 MB to 64 MB of vertices, drawn.
  report("one_view_64x.glb", meshopt_shared_views(5600000, 1, true));
  // An ordinary meshopt file: a grid of 2 x 300^2 triangles with every mode and filter.
  const MeshoptPair grid = meshopt_grid_glbs(make_grid(300));
  report("grid_300.glb", grid.compressed);
  report("grid_300_plain.glb", grid.plain);
}

void write_seeds(const std::string& dir) {
  const GridMesh grid = make_grid(3);
  const std::string prefix = dir + "/compressed_";
  write(prefix + "draco.glb", draco_grid_glb(grid).bytes());
  write(prefix + "draco_corrupt.glb", corrupted(draco_grid_glb(grid), 0.5));
  Glb truncated = draco_grid_glb(grid);
  truncated.bin.resize(truncated.bin.size() / 2);
  truncated.doc["bufferViews"][0]["byteLength"] = truncated.bin.size();
  write(prefix + "draco_truncated.glb", truncated.bytes());
  const MeshoptPair meshopt = meshopt_grid_glbs(grid, 2);
  write(prefix + "meshopt_instanced.glb", meshopt.compressed.bytes());
  write(prefix + "instanced_plain.glb", meshopt.plain.bytes());
  write(prefix + "meshopt_corrupt.glb", corrupted(meshopt.compressed, 0.3));
  const Bytes rgba = rgba_pattern(4, 4);
  const Bytes webp = encode_webp_lossless(rgba, 4, 4), png = encode_png(rgba, 4, 4);
  Glb webp_only = textured_quad_glb({{"image/webp", webp}}, {{"extensions", {{"EXT_texture_webp", {{"source", 0}}}}}});
  webp_only.require("EXT_texture_webp");
  write(prefix + "webp.glb", webp_only.bytes());
  write(prefix + "webp_corrupt.glb", corrupted(webp_only, 0.9));
  write(prefix + "webp_and_png.glb",
        textured_quad_glb({{"image/png", png}, {"image/webp", webp}}, {{"source", 0}, {"extensions", {{"EXT_texture_webp", {{"source", 1}}}}}}).bytes());
  // Views that share their compressed bytes (a decompression bomb of the per-view bound), used by
  // accessors and not, and a filter that is not a name.
  write(prefix + "meshopt_shared_views.glb", meshopt_shared_views(64, 40, true).bytes());
  write(prefix + "meshopt_shared_unused.glb", meshopt_shared_views(64, 40, false).bytes());
  MeshoptPair numbered = meshopt_grid_glbs(grid);
  numbered.compressed.doc["bufferViews"][0]["extensions"]["EXT_meshopt_compression"]["filter"] = 5;
  write(prefix + "meshopt_filter_number.glb", numbered.compressed.bytes());
  // A lossless WebP whose header declares 16384 x 16384 over 4 x 4 pixels of data.
  Bytes huge = webp;
  if (huge.size() < 25 || std::memcmp(huge.data() + 12, "VP8L", 4) != 0) throw std::runtime_error("not a VP8L WebP");
  uint32_t bits = 0;
  std::memcpy(&bits, huge.data() + 21, 4);
  bits = (bits & 0xf0000000u) | 0x0fffffffu;  // width - 1 and height - 1: 14 bits each, all set
  std::memcpy(huge.data() + 21, &bits, 4);
  Glb huge_webp = textured_quad_glb({{"image/webp", huge}}, {{"extensions", {{"EXT_texture_webp", {{"source", 0}}}}}});
  huge_webp.require("EXT_texture_webp");
  write(prefix + "webp_huge_dimensions.glb", huge_webp.bytes());
  const Bytes ktx2 = {0xAB, 'K', 'T', 'X', ' ', '2', '0', 0xBB, '\r', '\n', 0x1A, '\n'};
  Glb basisu = textured_quad_glb({{"image/png", png}, {"image/ktx2", ktx2}},
                                 {{"source", 0}, {"extensions", {{"KHR_texture_basisu", {{"source", 1}}}}}});
  basisu.doc["extensionsUsed"] = {"KHR_texture_basisu"};
  write(prefix + "basisu_fallback.glb", basisu.bytes());
  basisu.doc["extensionsRequired"] = {"KHR_texture_basisu"};
  write(prefix + "basisu_required.glb", basisu.bytes());
}

void write_draco_pair(int side, const std::string& dir) {
  const GridMesh grid = make_grid(side);
  write(dir + "/grid_plain.glb", plain_grid_glb(grid).bytes());
  write(dir + "/grid_draco.glb", draco_grid_glb(grid).bytes());
  const DracoQuantization blender;
  write(dir + "/grid_draco_quantized.glb", draco_grid_glb(grid, &blender).bytes());
  std::printf("wrote %s/grid_plain.glb, grid_draco.glb and grid_draco_quantized.glb: %zu triangles\n", dir.c_str(),
              grid.indices.size() / 3);
}

// ---------------------------------------------------------------------------------------- draco-glb

Bytes read(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path);
  return Bytes(std::istreambuf_iterator<char>(in), {});
}

// A GLB's JSON and BIN chunks.
Glb parse_glb(const Bytes& bytes) {
  auto u32 = [&](size_t at) {
    if (at + 4 > bytes.size()) throw std::runtime_error("not a GLB");
    uint32_t v;
    std::memcpy(&v, bytes.data() + at, 4);
    return v;
  };
  const uint32_t json_length = u32(12);
  Glb glb;
  glb.doc = json::parse(bytes.begin() + 20, bytes.begin() + 20 + json_length);
  const size_t bin_at = 20 + json_length;
  if (bin_at + 8 <= bytes.size()) glb.bin.assign(bytes.begin() + bin_at + 8, bytes.begin() + bin_at + 8 + u32(bin_at));
  glb.doc.erase("buffers");
  return glb;
}

template <typename T>
std::vector<T> accessor_values(const Glb& glb, int accessor, size_t components) {
  const json& a = glb.doc["accessors"][accessor];
  const json& v = glb.doc["bufferViews"][a["bufferView"].get<int>()];
  const size_t at = v.value("byteOffset", 0) + a.value("byteOffset", 0);
  std::vector<T> out(a["count"].get<size_t>() * components);
  std::memcpy(out.data(), glb.bin.data() + at, out.size() * sizeof(T));
  return out;
}

GridMesh primitive_mesh(const Glb& glb, const json& primitive) {
  GridMesh mesh;
  const json& attributes = primitive["attributes"];
  mesh.positions = accessor_values<float>(glb, attributes["POSITION"], 3);
  mesh.normals = accessor_values<float>(glb, attributes["NORMAL"], 3);
  mesh.uvs = accessor_values<float>(glb, attributes["TEXCOORD_0"], 2);
  const int indices = primitive["indices"];
  if (glb.doc["accessors"][indices]["componentType"] == 5123) {
    for (uint16_t i : accessor_values<uint16_t>(glb, indices, 1)) mesh.indices.push_back(i);
  } else {
    mesh.indices = accessor_values<uint32_t>(glb, indices, 1);
  }
  return mesh;
}

// The images' bytes, copied to a new BIN with the Draco data; the old geometry views are gone.
void write_draco_glb(const std::string& in, const std::string& out) {
  const Glb source = parse_glb(read(in));
  Glb result;
  result.doc = source.doc;
  result.doc["bufferViews"] = json::array();
  result.doc["accessors"] = json::array();
  for (json& image : result.doc["images"]) {
    const json& view = source.doc["bufferViews"][image["bufferView"].get<int>()];
    image["bufferView"] = result.view(source.bin.data() + view.value("byteOffset", 0), view["byteLength"].get<size_t>());
  }
  for (json& mesh : result.doc["meshes"])
    for (json& primitive : mesh["primitives"]) {
      const DracoQuantization blender;
      Glb compressed = draco_grid_glb(primitive_mesh(source, primitive), &blender);
      const json& compressed_primitive = compressed.doc["meshes"][0]["primitives"][0];
      json ext = compressed_primitive["extensions"]["KHR_draco_mesh_compression"];
      ext["bufferView"] = result.view(compressed.bin.data(), compressed.bin.size());
      json attributes = json::object();
      for (auto& [semantic, index] : compressed_primitive["attributes"].items()) {
        result.doc["accessors"].push_back(compressed.doc["accessors"][index.get<int>()]);
        attributes[semantic] = result.doc["accessors"].size() - 1;
      }
      result.doc["accessors"].push_back(compressed.doc["accessors"][compressed_primitive["indices"].get<int>()]);
      primitive["attributes"] = attributes;
      primitive["indices"] = result.doc["accessors"].size() - 1;
      primitive["extensions"]["KHR_draco_mesh_compression"] = ext;
    }
  result.require("KHR_draco_mesh_compression");
  write(out, result.bytes());
  std::printf("wrote %s (%zu bytes of BIN)\n", out.c_str(), result.bin.size());
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const std::string mode = argc > 1 ? argv[1] : "";
    if (mode == "seeds" && argc == 3) {
      write_seeds(argv[2]);
    } else if (mode == "draco-pair" && argc == 4) {
      write_draco_pair(std::atoi(argv[2]), argv[3]);
    } else if (mode == "meshopt-bombs" && argc == 3) {
      write_meshopt_bombs(argv[2]);
    } else if (mode == "draco-glb" && argc == 4) {
      write_draco_glb(argv[2], argv[3]);
    } else {
      std::fprintf(stderr, "usage: %s seeds DIR | draco-pair SIDE DIR | meshopt-bombs DIR | draco-glb IN.glb OUT.glb\n", argv[0]);
      return 2;
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "make_compressed_gltf: %s\n", e.what());
    return 1;
  }
  return 0;
}
