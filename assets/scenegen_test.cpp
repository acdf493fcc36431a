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
using pxf::scenegen::sceneNames;

namespace {

const fs::path kAssets = fs::path(PXF_SOURCE_DIR) / "assets";

struct Expectation {
  std::string name;
  size_t minTriangles, maxTriangles;
  bool emissiveMaterial;  // has area lights
  bool sun;               // has a KHR_lights_punctual directional light
  bool environment;       // ships environment.exr
  bool allHv;             // scene extras ask for --all-hv
};

const std::vector<Expectation>& expectations() {
  static const std::vector<Expectation> table = {
      {"cornell", 1000, 20000, true, false, false, false},
      {"atrium", 5000, 300000, false, true, true, false},
      {"kitchen", 2000, 300000, true, false, false, false},
      {"envmap", 10000, 300000, false, false, true, true},
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
void collectExtensions(const tinygltf::Value& value, std::set<std::string>& out) {
  if (value.IsArray()) {
    for (size_t i = 0; i < value.ArrayLen(); ++i) collectExtensions(value.Get(int(i)), out);
  } else if (value.IsObject()) {
    for (const std::string& key : value.Keys()) {
      const tinygltf::Value& child = value.Get(key);
      if (key == "extensions" && child.IsObject()) {
        for (const std::string& ext : child.Keys()) out.insert(ext);
      }
      collectExtensions(child, out);
    }
  }
}

void collectExtensions(const tinygltf::ExtensionMap& map, std::set<std::string>& out) {
  for (const auto& [name, value] : map) {
    out.insert(name);
    collectExtensions(value, out);
  }
}

std::set<std::string> extensionsInUse(const tinygltf::Model& model) {
  std::set<std::string> used;
  for (const tinygltf::Material& m : model.materials) {
    collectExtensions(m.extensions, used);
    collectExtensions(m.pbrMetallicRoughness.baseColorTexture.extensions, used);
    collectExtensions(m.pbrMetallicRoughness.metallicRoughnessTexture.extensions, used);
    collectExtensions(m.normalTexture.extensions, used);
    collectExtensions(m.emissiveTexture.extensions, used);
  }
  for (const tinygltf::Node& node : model.nodes) collectExtensions(node.extensions, used);
  if (!model.lights.empty()) used.insert("KHR_lights_punctual");
  return used;
}

size_t triangleCount(const tinygltf::Model& model) {
  size_t triangles = 0;
  for (const tinygltf::Node& node : model.nodes) {
    if (node.mesh < 0) continue;
    for (const tinygltf::Primitive& p : model.meshes[size_t(node.mesh)].primitives) {
      triangles += model.accessors[size_t(p.indices)].count / 3;
    }
  }
  return triangles;
}

std::string readFile(const fs::path& path) {
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
  bool cameraNode = false;
  for (const auto& node : model.nodes) cameraNode |= node.camera == 0;
  EXPECT_TRUE(cameraNode);

  bool emissive = false;
  for (const auto& m : model.materials) {
    for (double c : m.emissiveFactor) emissive |= c > 0.0;
  }
  EXPECT_EQ(emissive, e.emissiveMaterial);
  bool sun = false;
  for (const auto& light : model.lights) sun |= light.type == "directional";
  EXPECT_EQ(sun, e.sun);
  EXPECT_EQ(fs::exists(kAssets / e.name / "environment.exr"), e.environment);

  const tinygltf::Value& pxf = model.scenes[0].extras.Get("pxf");
  EXPECT_EQ(pxf.Get("all_hv").IsBool() && pxf.Get("all_hv").Get<bool>(), e.allHv);

  const size_t triangles = triangleCount(model);
  EXPECT_GE(triangles, e.minTriangles);
  EXPECT_LE(triangles, e.maxTriangles);
  for (const auto& image : model.images) {
    EXPECT_GE(image.width, 256) << image.uri;
    EXPECT_LE(image.width, 1024) << image.uri;
  }
}

TEST_P(SceneTest, DeclaresExactlyTheExtensionsItUses) {
  const tinygltf::Model model = load(GetParam().name);
  const std::set<std::string> declared(model.extensionsUsed.begin(), model.extensionsUsed.end());
  EXPECT_EQ(declared.size(), model.extensionsUsed.size()) << "duplicates in extensionsUsed";
  EXPECT_EQ(declared, extensionsInUse(model));
  EXPECT_TRUE(model.extensionsRequired.empty());
}

TEST_P(SceneTest, CommittedFilesMatchAFreshRun) {
  const std::string name = GetParam().name;
  const fs::path fresh = fs::temp_directory_path() / ("pxf_scenegen_test_" + std::to_string(::getpid()));
  std::string error;
  ASSERT_TRUE(pxf::scenegen::writeScene(name, fresh.string(), &error)) << error;
  std::set<std::string> committedFiles, freshFiles;
  for (const auto& entry : fs::directory_iterator(kAssets / name)) committedFiles.insert(entry.path().filename());
  for (const auto& entry : fs::directory_iterator(fresh / name)) freshFiles.insert(entry.path().filename());
  EXPECT_EQ(committedFiles, freshFiles);
  for (const std::string& file : freshFiles) {
    EXPECT_TRUE(readFile(kAssets / name / file) == readFile(fresh / name / file))
        << name << "/" << file << " differs from a fresh run: regenerate the assets (see assets/README.md)";
  }
  fs::remove_all(fresh);
}

TEST(Scenegen, EverySceneHasExpectations) {
  std::vector<std::string> expected;
  for (const auto& e : expectations()) expected.push_back(e.name);
  EXPECT_EQ(expected, sceneNames());
}

INSTANTIATE_TEST_SUITE_P(BuiltIn, SceneTest, ::testing::ValuesIn(expectations()),
                         [](const auto& info) { return info.param.name; });

}  // namespace
