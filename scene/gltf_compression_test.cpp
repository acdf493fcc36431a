// Compressed and extended glTF: each decoder's file loads to exactly the
// triangles or texels of its uncompressed twin; malformed data and unsupported requirements are
// one-line errors; EXT_mesh_gpu_instancing counts against the limits like nodes do. The files are
// written by the libraries' encoders (testing/gltf_compressed_fixtures.h).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <tuple>

#include "core/error.h"
#include "scene/gltf_meshopt.h"
#include "scene/load.h"
#include "testing/gltf_compressed_fixtures.h"

namespace pxf {
namespace {

using namespace gltf_fixtures;

Scene load(const Bytes& bytes, const LoadLimits& limits = {}) {
  return load_scene_from_memory(bytes, "test.glb", "/nonexistent-pxf-test-folder", limits);
}

std::string error_of(const Bytes& bytes, const LoadLimits& limits = {}) {
  try {
    load(bytes, limits);
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    return message;
  }
  ADD_FAILURE() << "expected a pxf::Error";
  return "";
}

bool has_warning(const Scene& scene, const std::string& text) {
  return std::any_of(scene.warnings.begin(), scene.warnings.end(),
                     [&](const std::string& w) { return w.find(text) != std::string::npos; });
}

// Every triangle as its three corners (position, normal, uv), rotated to start at the smallest
// corner, all sorted: equal for two loads that give the same surface whatever the vertex order.
using Corner = std::array<float, 8>;
using Triangle = std::array<Corner, 3>;
std::vector<Triangle> canonical_triangles(const Scene& scene) {
  std::vector<Triangle> out;
  for (const Mesh& mesh : scene.meshes)
    for (const glm::uvec3& t : mesh.triangles) {
      Triangle tri;
      for (int k = 0; k < 3; ++k) {
        const uint32_t v = t[k];
        const glm::vec2 uv = mesh.uv0.empty() ? glm::vec2(0.0f) : mesh.uv0[v];
        tri[k] = {mesh.positions[v].x, mesh.positions[v].y, mesh.positions[v].z, mesh.normals[v].x, mesh.normals[v].y,
                  mesh.normals[v].z, uv.x, uv.y};
      }
      std::rotate(tri.begin(), std::min_element(tri.begin(), tri.end()), tri.end());
      out.push_back(tri);
    }
  std::sort(out.begin(), out.end());
  return out;
}

// ---------------------------------------------------------------------------------------- Draco

TEST(GltfDraco, LoadsExactlyTheTrianglesOfItsUncompressedTwin) {
  const GridMesh grid = make_grid(12);
  const Scene plain = load(plain_grid_glb(grid).bytes());
  const Scene draco = load(draco_grid_glb(grid).bytes());
  ASSERT_EQ(plain.triangle_count(), 2u * 12 * 12);
  EXPECT_EQ(canonical_triangles(draco), canonical_triangles(plain));
  EXPECT_FALSE(has_warning(draco, "KHR_draco_mesh_compression"));
}

TEST(GltfDraco, MalformedDataIsAOneLineError) {
  // Unquantized values are stored raw, so only the header and connectivity can be found malformed.
  Glb glb = draco_grid_glb(make_grid(4));
  glb.bin[2] ^= 0x5a;  // the "DRACO" magic
  std::string message = error_of(glb.bytes());
  EXPECT_EQ(message.rfind("test.glb: mesh 0 primitive 0: Draco data could not be decoded (", 0), 0u) << message;

  glb = draco_grid_glb(make_grid(4));
  glb.bin.resize(10);  // the view now reaches past its buffer
  glb.doc["bufferViews"][0]["byteLength"] = 10;
  message = error_of(glb.bytes());
  EXPECT_NE(message.find("Draco data could not be decoded"), std::string::npos) << message;
}

TEST(GltfDraco, DecodedCountsMustMatchTheAccessors) {
  Glb glb = draco_grid_glb(make_grid(4));
  glb.doc["accessors"][3]["count"] = 3;  // indices: 1 triangle, the data has 32
  std::string message = error_of(glb.bytes());
  EXPECT_NE(message.find("decodes to 32 triangles"), std::string::npos) << message;

  glb = draco_grid_glb(make_grid(4));
  glb.doc["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"]["attributes"]["NORMAL"] = 17;
  message = error_of(glb.bytes());
  EXPECT_NE(message.find("NORMAL: the Draco data has no attribute 17"), std::string::npos) << message;
}

// ---------------------------------------------------------------------------------------- meshopt

TEST(GltfMeshopt, LoadsExactlyTheTrianglesOfItsUncompressedTwin) {
  const MeshoptPair files = meshopt_grid_glbs(make_grid(10));
  const Scene plain = load(files.plain.bytes());
  const Scene meshopt = load(files.compressed.bytes());
  EXPECT_EQ(plain.triangle_count(), 200u + 100u);  // TRIANGLES and INDICES primitives
  EXPECT_EQ(canonical_triangles(meshopt), canonical_triangles(plain));
}

TEST(GltfMeshopt, FiltersAndInstancingMatchTheTwin) {
  const MeshoptPair files = meshopt_grid_glbs(make_grid(6), 3);
  const Scene plain = load(files.plain.bytes());
  const Scene meshopt = load(files.compressed.bytes());
  EXPECT_EQ(meshopt.meshes.size(), 3u * 2);
  EXPECT_EQ(canonical_triangles(meshopt), canonical_triangles(plain));
}

TEST(GltfMeshopt, MalformedDataIsAOneLineError) {
  MeshoptPair files = meshopt_grid_glbs(make_grid(6));
  Glb& glb = files.compressed;
  const json ext = glb.doc["bufferViews"][3]["extensions"]["EXT_meshopt_compression"];  // TRIANGLES
  std::fill_n(glb.bin.begin() + ext["byteOffset"].get<size_t>(), ext["byteLength"].get<size_t>(), 0xff);
  std::string message = error_of(glb.bytes());
  EXPECT_NE(message.find("test.glb: bufferView 3: malformed EXT_meshopt_compression data (TRIANGLES"), std::string::npos)
      << message;

  files = meshopt_grid_glbs(make_grid(6));
  files.compressed.doc["bufferViews"][0]["extensions"]["EXT_meshopt_compression"]["count"] = 1u << 30;
  message = error_of(files.compressed.bytes());
  EXPECT_NE(message.find("bufferView 0: claims 1073741824 elements"), std::string::npos) << message;

  files = meshopt_grid_glbs(make_grid(6));
  files.compressed.doc["bufferViews"][1]["extensions"]["EXT_meshopt_compression"]["filter"] = "QUATERNION";
  message = error_of(files.compressed.bytes());
  EXPECT_NE(message.find("filter 'QUATERNION' does not fit byteStride 4"), std::string::npos) << message;

  files = meshopt_grid_glbs(make_grid(6));
  files.compressed.doc["bufferViews"][1]["extensions"]["EXT_meshopt_compression"]["mode"] = "SPLINES";
  message = error_of(files.compressed.bytes());
  EXPECT_NE(message.find("unknown mode 'SPLINES'"), std::string::npos) << message;
}

// Many views may name the same compressed bytes: the decoded bytes of all used views are bounded by
// the distinct compressed bytes, each counted once (else a small file can decode to gigabytes).
TEST(GltfMeshopt, ViewsSharingCompressedBytesAreBoundedTogether) {
  MeshoptPair files = meshopt_grid_glbs(make_grid(10));
  json& doc = files.compressed.doc;
  const json view = doc["bufferViews"][0];
  json accessor;
  for (const json& a : doc["accessors"])
    if (a.value("bufferView", -1) == 0) accessor = a;
  ASSERT_FALSE(accessor.is_null());
  for (int k = 0; k < 2000; ++k) {
    accessor["bufferView"] = doc["bufferViews"].size();
    doc["bufferViews"].push_back(view);
    doc["accessors"].push_back(accessor);
  }
  const std::string message = error_of(files.compressed.bytes());
  EXPECT_NE(message.find("EXT_meshopt_compression bufferViews claim"), std::string::npos) << message;
  EXPECT_NE(message.find("distinct compressed bytes"), std::string::npos) << message;
}

// Only the views that accessors (or images) use are decoded, and their decoded bytes are in the
// memory estimate, which is checked before they are decoded.
TEST(GltfMeshopt, OnlyUsedViewsAreDecodedAndTheyAreInTheEstimate) {
  MeshoptPair files = meshopt_grid_glbs(make_grid(10));
  const Scene plain = load(files.plain.bytes());
  const Scene compressed = load(files.compressed.bytes());
  uint64_t decoded = 0;
  for (const json& v : files.compressed.doc["bufferViews"])
    decoded += v["extensions"]["EXT_meshopt_compression"]["count"].get<uint64_t>() *
               v["extensions"]["EXT_meshopt_compression"]["byteStride"].get<uint64_t>();
  EXPECT_EQ(compressed.estimated_load_bytes, plain.estimated_load_bytes + decoded);

  // An unused view of garbage is never decoded; a used one is (MalformedDataIsAOneLineError).
  Glb& glb = files.compressed;
  json garbage = glb.doc["bufferViews"][3];
  garbage["extensions"]["EXT_meshopt_compression"]["byteOffset"] = glb.bin.size();
  glb.bin.insert(glb.bin.end(), garbage["extensions"]["EXT_meshopt_compression"]["byteLength"].get<size_t>(), 0xff);
  glb.doc["bufferViews"].push_back(garbage);
  EXPECT_EQ(canonical_triangles(load(glb.bytes())), canonical_triangles(plain));

  // A decode that the memory available cannot hold is refused before it is decoded.
  LoadLimits tight;
  tight.available_memory = plain.estimated_load_bytes + decoded / 2;
  const std::string message = error_of(files.compressed.bytes(), tight);
  EXPECT_NE(message.find("of decoded meshopt data"), std::string::npos) << message;
}

// A filter or mode that is not a name is refused by name, not taken as NONE.
TEST(GltfMeshopt, AFilterThatIsNotANameIsRefusedByName) {
  MeshoptPair files = meshopt_grid_glbs(make_grid(6));
  files.compressed.doc["bufferViews"][0]["extensions"]["EXT_meshopt_compression"]["filter"] = 5;
  std::string message = error_of(files.compressed.bytes());
  EXPECT_NE(message.find("test.glb: bufferView 0: filter 5 is not a name"), std::string::npos) << message;

  files = meshopt_grid_glbs(make_grid(6));
  files.compressed.doc["bufferViews"][0]["extensions"]["EXT_meshopt_compression"]["filter"] = "SPHERICAL";
  message = error_of(files.compressed.bytes());
  EXPECT_NE(message.find("unknown filter 'SPHERICAL'"), std::string::npos) << message;
}

// The 64-fold bound of gltf_meshopt.h holds for the most compressible data there is.
TEST(GltfMeshopt, CodecsExpandAtMostTheBoundTheLoaderChecks) {
  const size_t count = 1 << 16, stride = 16;
  const Bytes zeros(count * stride, 0);
  Bytes encoded(meshopt_encodeVertexBufferBound(count, stride));
  encoded.resize(meshopt_encodeVertexBuffer(encoded.data(), encoded.size(), zeros.data(), count, stride));
  EXPECT_LE(zeros.size(), gltf::kMaxMeshoptExpansion * encoded.size());
  const std::vector<uint32_t> same(3 * count, 0);
  encoded.assign(meshopt_encodeIndexBufferBound(same.size(), 1), 0);
  encoded.resize(meshopt_encodeIndexBuffer(encoded.data(), encoded.size(), same.data(), same.size()));
  EXPECT_LE(same.size() * 4, gltf::kMaxMeshoptExpansion * encoded.size());
}

// ---------------------------------------------------------------------------------------- WebP

constexpr int kWidth = 5, kHeight = 3;

// The base color texture's stored 8-bit texels.
Bytes base_color_texels(const Scene& scene) {
  EXPECT_EQ(scene.textures.size(), 1u);
  if (scene.textures.empty() || !scene.textures[0].is_8bit()) return {};
  EXPECT_EQ(scene.textures[0].width, kWidth);
  return *scene.textures[0].texels8;
}

TEST(GltfWebp, LoadsExactlyTheTexelsOfItsPngTwin) {
  const Bytes rgba = rgba_pattern(kWidth, kHeight);
  const Bytes webp = encode_webp_lossless(rgba, kWidth, kHeight), png = encode_png(rgba, kWidth, kHeight);
  const Scene from_png = load(textured_quad_glb({{"image/png", png}}, {{"source", 0}}).bytes());
  Glb webp_only = textured_quad_glb({{"image/webp", webp}}, {{"extensions", {{"EXT_texture_webp", {{"source", 0}}}}}});
  webp_only.require("EXT_texture_webp");
  const Scene from_webp = load(webp_only.bytes());
  EXPECT_EQ(base_color_texels(from_png), rgba);
  EXPECT_EQ(base_color_texels(from_webp), rgba);
}

// With both, the WebP image is the one decoded: here the PNG is another picture.
TEST(GltfWebp, WebpIsPreferredToTheFallbackSource) {
  const Bytes rgba = rgba_pattern(kWidth, kHeight);
  Bytes other = rgba;
  for (unsigned char& c : other) c = static_cast<unsigned char>(c / 2 + 1);
  const Glb glb = textured_quad_glb({{"image/png", encode_png(other, kWidth, kHeight)},
                                     {"image/webp", encode_webp_lossless(rgba, kWidth, kHeight)}},
                                    {{"source", 0}, {"extensions", {{"EXT_texture_webp", {{"source", 1}}}}}});
  EXPECT_EQ(base_color_texels(load(glb.bytes())), rgba);
}

TEST(GltfWebp, MalformedWebpIsAWarningLikeAnyBadImage) {
  Bytes webp = encode_webp_lossless(rgba_pattern(kWidth, kHeight), kWidth, kHeight);
  std::fill(webp.begin() + 20, webp.end(), 0x33);
  const Scene scene = load(textured_quad_glb({{"image/webp", webp}}, {{"extensions", {{"EXT_texture_webp", {{"source", 0}}}}}}).bytes());
  EXPECT_TRUE(scene.textures.empty());
  EXPECT_TRUE(has_warning(scene, "could not be loaded")) << scene.warnings.size();
}

// ---------------------------------------------------------------------------------------- KTX2

TEST(GltfBasisu, RequiredIsRefusedByNameUsedFallsBackToThePng) {
  const Bytes rgba = rgba_pattern(kWidth, kHeight);
  const Bytes ktx2 = {0xAB, 'K', 'T', 'X', ' ', '2', '0', 0xBB, '\r', '\n', 0x1A, '\n'};
  Glb glb = textured_quad_glb({{"image/png", encode_png(rgba, kWidth, kHeight)}, {"image/ktx2", ktx2}},
                              {{"source", 0}, {"extensions", {{"KHR_texture_basisu", {{"source", 1}}}}}});
  glb.doc["extensionsUsed"] = {"KHR_texture_basisu"};
  const Scene used = load(glb.bytes());
  EXPECT_EQ(base_color_texels(used), rgba);
  EXPECT_TRUE(has_warning(used, "KTX2 images cannot be decoded; its textures use their PNG/JPEG source"));
  EXPECT_FALSE(has_warning(used, "ignoring unsupported extensions"));

  glb.doc["extensionsRequired"] = {"KHR_texture_basisu"};
  const std::string message = error_of(glb.bytes());
  EXPECT_EQ(message.rfind("test.glb: requires KHR_texture_basisu", 0), 0u) << message;

  Glb ktx2_only = textured_quad_glb({{"image/ktx2", ktx2}}, {{"extensions", {{"KHR_texture_basisu", {{"source", 0}}}}}});
  ktx2_only.doc["extensionsUsed"] = {"KHR_texture_basisu"};
  const Scene without = load(ktx2_only.bytes());
  EXPECT_TRUE(without.textures.empty());
  EXPECT_TRUE(has_warning(without, "has only a KTX2 image (KHR_texture_basisu)"));
}

// ---------------------------------------------------------------------------------------- required

// Today's Draco failure ("accessor[0] invalid bufferView") came from tinygltf before the
// extension check: an unsupported requirement is now named whatever else is wrong with the file.
TEST(GltfRequiredExtensions, NamedBeforeAnyAccessorError) {
  Glb glb = draco_grid_glb(make_grid(2));
  glb.require("EXT_made_up");
  glb.doc["accessors"][3].erase("componentType");
  glb.doc["meshes"][0]["primitives"][0].erase("extensions");
  const std::string message = error_of(glb.bytes());
  EXPECT_EQ(message, "test.glb: required extension EXT_made_up is not supported");
}

// ---------------------------------------------------------------------------------------- instancing

TEST(GltfInstancing, InstancesCountLikeNodesAgainstTheLimitsAndTheEstimate) {
  constexpr int kInstances = 4;
  const MeshoptPair files = meshopt_grid_glbs(make_grid(3), kInstances);
  const Scene instanced = load(files.plain.bytes());
  const size_t per_instance = 18 + 9;  // the two primitives
  EXPECT_EQ(instanced.triangle_count(), kInstances * per_instance);

  // The same scene with one node per instance: the same triangles and estimate.
  Glb nodes = files.plain;
  json node = nodes.doc["nodes"][0];
  node["extensions"].erase("EXT_mesh_gpu_instancing");
  nodes.doc["nodes"] = json::array();
  for (int i = 0; i < kInstances; ++i) nodes.doc["nodes"].push_back(node);
  nodes.doc["scenes"][0]["nodes"] = {0, 1, 2, 3};
  const Scene flat = load(nodes.bytes());
  EXPECT_EQ(flat.estimated_load_bytes, instanced.estimated_load_bytes);

  LoadLimits limits;
  limits.max_triangles = kInstances * per_instance - 1;
  const std::string message = error_of(files.plain.bytes(), limits);
  EXPECT_NE(message.find("the scene instances " + std::to_string(kInstances * per_instance) + " triangles"),
            std::string::npos) << message;
}

TEST(GltfInstancing, TransformsFollowTheNodeAndDisagreeingCountsFail) {
  const MeshoptPair files = meshopt_grid_glbs(make_grid(1), 2);
  Glb glb = files.plain;
  glb.doc["nodes"][0]["translation"] = {0, 0, 10};
  const Scene scene = load(glb.bytes());
  ASSERT_EQ(scene.meshes.size(), 4u);
  // Instance 1: translated by (1.5, 0.25, -0.5) after the node's (0, 0, 10); scaled by (1.5, 1, 0.75) and
  // turned by 0.7 rad about y, which leaves a point's y scaled only: corner (-0.5, -0.5, z) at y = -0.25.
  float lowest_y = 1e9f;
  for (const glm::vec3& p : scene.meshes[2].positions) lowest_y = std::min(lowest_y, p.y);
  EXPECT_NEAR(lowest_y, 0.25f - 0.5f, 1e-3f);
  for (const glm::vec3& p : scene.meshes[2].positions) EXPECT_GT(p.z, 5.0f);

  const int scale = glb.doc["nodes"][0]["extensions"]["EXT_mesh_gpu_instancing"]["attributes"]["SCALE"];
  glb.doc["accessors"][scale]["count"] = 1;
  const std::string message = error_of(glb.bytes());
  EXPECT_NE(message.find("node 0 EXT_mesh_gpu_instancing SCALE: 1 instances, the other attributes have 2"), std::string::npos)
      << message;
}

}  // namespace
}  // namespace pxf
