// Checks the committed built-in scenes: each loads cleanly with tinygltf, has a camera, the
// emitters it promises and a sane triangle count, declares exactly the extensions it uses, and
// is byte-identical to a fresh run of the generator (so the assets are deterministic and current).
#include <gtest/gtest.h>
#include <tiny_gltf.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <sstream>
#include <unistd.h>

#include "scenes.h"

namespace fs = std::filesystem;
using pxf::scenegen::scene_names;

namespace {

const fs::path kAssets = fs::path(PXF_SOURCE_DIR) / "assets";

struct Expectation {
  std::string name;
  size_t min_triangles, max_triangles;
  bool emissive_material;  // has area lights
  bool sun;               // has a KHR_lights_punctual directional light
  bool environment;       // ships environment.exr
  bool all_hv;             // scene extras ask for --all-hv
};

const std::vector<Expectation>& expectations() {
  static const std::vector<Expectation> table = {
      {"cornell", 1000, 20000, true, false, false, false},
      {"atrium", 5000, 300000, false, true, true, false},
      {"kitchen", 2000, 300000, true, false, false, false},
      {"envmap", 10000, 300000, false, false, true, false},
      {"product", 10000, 300000, false, false, true, false},
      {"window", 2000, 300000, false, false, true, false},
  };
  return table;
}

tinygltf::Model load(const std::string& name) {
  tinygltf::TinyGLTF loader;
  tinygltf::Model model;
  std::string err, warn;
  const fs::path path = kAssets / name / (name + ".gltf");
  const bool ok = loader.LoadASCIIFromFile(&model, &err, &warn, path.string());
  EXPECT_TRUE(ok) << path;
  EXPECT_EQ(err, "") << path;
  EXPECT_EQ(warn, "") << path;
  return model;
}

// Every extension name that appears as a key of an "extensions" object below `value`.
void collect_extensions(const tinygltf::Value& value, std::set<std::string>& out) {
  if (value.IsArray()) {
    for (size_t i = 0; i < value.ArrayLen(); ++i) collect_extensions(value.Get(int(i)), out);
  } else if (value.IsObject()) {
    for (const std::string& key : value.Keys()) {
      const tinygltf::Value& child = value.Get(key);
      if (key == "extensions" && child.IsObject()) {
        for (const std::string& ext : child.Keys()) out.insert(ext);
      }
      collect_extensions(child, out);
    }
  }
}

void collect_extensions(const tinygltf::ExtensionMap& map, std::set<std::string>& out) {
  for (const auto& [name, value] : map) {
    out.insert(name);
    collect_extensions(value, out);
  }
}

std::set<std::string> extensions_in_use(const tinygltf::Model& model) {
  std::set<std::string> used;
  for (const tinygltf::Material& m : model.materials) {
    collect_extensions(m.extensions, used);
    collect_extensions(m.pbrMetallicRoughness.baseColorTexture.extensions, used);
    collect_extensions(m.pbrMetallicRoughness.metallicRoughnessTexture.extensions, used);
    collect_extensions(m.normalTexture.extensions, used);
    collect_extensions(m.emissiveTexture.extensions, used);
  }
  for (const tinygltf::Node& node : model.nodes) collect_extensions(node.extensions, used);
  if (!model.lights.empty()) used.insert("KHR_lights_punctual");
  return used;
}

size_t triangle_count(const tinygltf::Model& model) {
  size_t triangles = 0;
  for (const tinygltf::Node& node : model.nodes) {
    if (node.mesh < 0) continue;
    for (const tinygltf::Primitive& p : model.meshes[size_t(node.mesh)].primitives) {
      triangles += model.accessors[size_t(p.indices)].count / 3;
    }
  }
  return triangles;
}

std::string read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

class SceneTest : public ::testing::TestWithParam<Expectation> {};

TEST_P(SceneTest, LoadsWithCameraEmittersAndSaneSize) {
  const Expectation& e = GetParam();
  const tinygltf::Model model = load(e.name);
  ASSERT_EQ(model.scenes.size(), 1u);
  ASSERT_EQ(model.cameras.size(), 1u);
  EXPECT_EQ(model.cameras[0].type, "perspective");
  bool camera_node = false;
  for (const auto& node : model.nodes) camera_node |= node.camera == 0;
  EXPECT_TRUE(camera_node);

  bool emissive = false;
  for (const auto& m : model.materials) {
    for (double c : m.emissiveFactor) emissive |= c > 0.0;
  }
  EXPECT_EQ(emissive, e.emissive_material);
  bool sun = false;
  for (const auto& light : model.lights) sun |= light.type == "directional";
  EXPECT_EQ(sun, e.sun);
  EXPECT_EQ(fs::exists(kAssets / e.name / "environment.exr"), e.environment);

  const tinygltf::Value& pxf = model.scenes[0].extras.Get("pxf");
  EXPECT_EQ(pxf.Get("all_hv").IsBool() && pxf.Get("all_hv").Get<bool>(), e.all_hv);

  const size_t triangles = triangle_count(model);
  EXPECT_GE(triangles, e.min_triangles);
  EXPECT_LE(triangles, e.max_triangles);
  for (const auto& image : model.images) {
    EXPECT_GE(image.width, 256) << image.uri;
    EXPECT_LE(image.width, 1024) << image.uri;
  }
}

// Reads accessor `index` (tightly packed floats or unsigned indices) as doubles.
template <typename T>
std::vector<T> read_accessor(const tinygltf::Model& model, int index) {
  const tinygltf::Accessor& accessor = model.accessors[size_t(index)];
  const tinygltf::BufferView& view = model.bufferViews[size_t(accessor.bufferView)];
  const unsigned char* data = model.buffers[size_t(view.buffer)].data.data() + view.byteOffset + accessor.byteOffset;
  const size_t components = size_t(tinygltf::GetNumComponentsInType(uint32_t(accessor.type)));
  std::vector<T> out(accessor.count * components);
  for (size_t i = 0; i < out.size(); ++i) {
    switch (accessor.componentType) {
      case TINYGLTF_COMPONENT_TYPE_FLOAT: out[i] = T(reinterpret_cast<const float*>(data)[i]); break;
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: out[i] = T(reinterpret_cast<const uint16_t*>(data)[i]); break;
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: out[i] = T(reinterpret_cast<const uint32_t*>(data)[i]); break;
      default: ADD_FAILURE() << "unexpected component type";
    }
  }
  return out;
}

// Every triangle is wound counter-clockwise around its vertex normals (front faces are the
// shaded sides), and every vertex has unit normal and a UV.
TEST_P(SceneTest, WindingAgreesWithNormals) {
  const tinygltf::Model model = load(GetParam().name);
  for (const tinygltf::Mesh& mesh : model.meshes) {
    for (const tinygltf::Primitive& primitive : mesh.primitives) {
      ASSERT_TRUE(primitive.attributes.count("NORMAL") && primitive.attributes.count("TEXCOORD_0")) << mesh.name;
      const auto p = read_accessor<double>(model, primitive.attributes.at("POSITION"));
      const auto n = read_accessor<double>(model, primitive.attributes.at("NORMAL"));
      const auto indices = read_accessor<uint32_t>(model, primitive.indices);
      size_t flipped = 0;
      for (size_t t = 0; t + 2 < indices.size(); t += 3) {
        const size_t a = 3 * indices[t], b = 3 * indices[t + 1], c = 3 * indices[t + 2];
        const double e1[3] = {p[b] - p[a], p[b + 1] - p[a + 1], p[b + 2] - p[a + 2]};
        const double e2[3] = {p[c] - p[a], p[c + 1] - p[a + 1], p[c + 2] - p[a + 2]};
        const double g[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
        double dot = 0.0;
        for (size_t v : {a, b, c}) dot += g[0] * n[v] + g[1] * n[v + 1] + g[2] * n[v + 2];
        flipped += dot <= 0.0;
      }
      EXPECT_EQ(flipped, 0u) << mesh.name;
      for (size_t v = 0; v < n.size(); v += 3) {
        ASSERT_NEAR(n[v] * n[v] + n[v + 1] * n[v + 1] + n[v + 2] * n[v + 2], 1.0, 1e-4) << mesh.name;
      }
    }
  }
}

TEST_P(SceneTest, DeclaresExactlyTheExtensionsItUses) {
  const tinygltf::Model model = load(GetParam().name);
  const std::set<std::string> declared(model.extensionsUsed.begin(), model.extensionsUsed.end());
  EXPECT_EQ(declared.size(), model.extensionsUsed.size()) << "duplicates in extensionsUsed";
  EXPECT_EQ(declared, extensions_in_use(model));
  EXPECT_TRUE(model.extensionsRequired.empty());
}

TEST_P(SceneTest, CommittedFilesMatchAFreshRun) {
  const std::string name = GetParam().name;
  const fs::path fresh = fs::temp_directory_path() / ("pxf_scenegen_test_" + std::to_string(::getpid()));
  pxf::scenegen::write_scene(name, fresh.string());
  std::set<std::string> committed_files, fresh_files;
  for (const auto& entry : fs::directory_iterator(kAssets / name)) committed_files.insert(entry.path().filename());
  for (const auto& entry : fs::directory_iterator(fresh / name)) fresh_files.insert(entry.path().filename());
  EXPECT_EQ(committed_files, fresh_files);
  for (const std::string& file : fresh_files) {
    EXPECT_TRUE(read_file(kAssets / name / file) == read_file(fresh / name / file))
        << name << "/" << file << " differs from a fresh run: regenerate the assets (see assets/README.md)";
  }
  fs::remove_all(fresh);
}

TEST(Scenegen, EverySceneHasExpectations) {
  std::vector<std::string> expected;
  for (const auto& e : expectations()) expected.push_back(e.name);
  EXPECT_EQ(expected, scene_names());
}

INSTANTIATE_TEST_SUITE_P(BuiltIn, SceneTest, ::testing::ValuesIn(expectations()),
                         [](const auto& info) { return info.param.name; });

}  // namespace
