// Scene inputs at the loader's limits, end to end through `pxf render`:
// a camera scaled or widened past the coordinate bound, JSON nested 20,000 deep, a texture
// transform of 3e38 and an environment map over --max-texture-size each end as a render or a
// one-line error, never as a signal or a lost render.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <tuple>

#include "image/image.h"
#include "tests/test_support.h"

namespace fs = std::filesystem;
using namespace pxf;

namespace {

struct Result {
  int code = -1;  // -1: killed by a signal
  std::string out, err;
};

std::string temp_dir(const std::string& name) { return test_support::temp_dir("scene_limits", name); }

Result run(const std::string& args) {
  const std::string base = temp_dir("io");
  fs::create_directories(base);
  const std::string cmd = std::string(PXF_EXECUTABLE) + " " + args + " >" + base + "/out 2>" + base + "/err";
  const int status = std::system(cmd.c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, test_support::slurp(base + "/out"), test_support::slurp(base + "/err")};
}

// The lines of `err` that are not progress bars.
std::string messages(const std::string& err) {
  std::string kept, line;
  std::istringstream in(err);
  while (std::getline(in, line))
    if (!line.empty() && line[0] != '[') kept += line + "\n";
  return kept;
}

size_t lines(const std::string& text) { return std::count(text.begin(), text.end(), '\n'); }

const std::string kPerspective = R"({"type":"perspective","perspective":{"yfov":0.8,"znear":0.01}})";

// A 2x2 quad under an emissive material (so that no default light is added) and a camera node;
// `camera_node` and `camera` are JSON members spliced in, `material_extra` into the material.
std::string write_scene(const std::string& dir, const std::string& name, const std::string& camera_node,
                        const std::string& camera = kPerspective,
                        const std::string& material_extra = "", const std::string& top_extra = "") {
  fs::create_directories(dir);
  const std::string path = dir + "/" + name;
  // Positions (-1,0,-1) (1,0,-1) (1,0,1) (-1,0,1), normals (unused), UVs, indices 0 1 2 0 2 3: 140 bytes.
  std::ofstream(path)
      << R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0,1]}],)"
      << R"("nodes":[{"mesh":0},{"camera":0,"translation":[0,3,3],"rotation":[-0.3826834,0,0,0.9238795])" << camera_node
      << R"(}],"meshes":[{"primitives":[{"attributes":{"POSITION":0,"TEXCOORD_0":1},"indices":2,"material":0}]}],)"
      << R"("cameras":[)" << camera << R"(],)"
      << R"("materials":[{"emissiveFactor":[1,1,1],"pbrMetallicRoughness":{"baseColorFactor":[0.8,0.7,0.6,1])" << material_extra
      << R"(}}],"bufferViews":[{"buffer":0,"byteLength":48},{"buffer":0,"byteOffset":96,"byteLength":32},)"
      << R"({"buffer":0,"byteOffset":128,"byteLength":12}],)"
      << R"("accessors":[{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[-1,0,-1],"max":[1,0,1]},)"
      << R"({"bufferView":1,"componentType":5126,"count":4,"type":"VEC2"},{"bufferView":2,"componentType":5123,"count":6,"type":"SCALAR"}],)"
      << R"("buffers":[{"byteLength":140,"uri":"data:application/octet-stream;base64,)"
      << "AACAvwAAAAAAAIC/AACAPwAAAAAAAIC/AACAPwAAAAAAAIA/AACAvwAAAAAAAIA/AAAAAAAAgD8AAAAAAAAAAAAAgD8AAAAAAAAAAAAAgD8AAAAAAAAAAAAAgD8AAAAAAAAAAAAAAAAAAIA/AAAAAAAAgD8AAIA/AAAAAAAAgD8AAAEAAgAAAAIAAwA="
      << R"("}])" << top_extra << "}";
  return path;
}

const char* kRender = "render --spp 1 --size 16x16 --threads 2";

TEST(SceneLimits, CameraScaledOrWidenedFarOutRendersOrIsOneLineNotAnAbort) {
  const std::string dir = temp_dir("camera");
  // Scale 2e19 overflowed the camera frame's normalization: NaN rays, an Embree assertion (SIGABRT).
  const Result scaled = run(std::string(kRender) + " --scene " + write_scene(dir, "scaled.gltf", R"(,"scale":[2e19,2e19,2e19])") +
                            " --out " + dir + "/scaled");
  EXPECT_EQ(scaled.code, 0) << scaled.err;
  EXPECT_TRUE(fs::exists(dir + "/scaled/final.exr"));
  // xmag/ymag 1e19 put the orthographic rays' origins past what Embree accepts.
  const std::string ortho = R"({"type":"orthographic","orthographic":{"xmag":1e19,"ymag":1e19,"znear":0.01,"zfar":100}})";
  const Result wide = run(std::string(kRender) + " --scene " + write_scene(dir, "ortho.gltf", "", ortho) + " --out " + dir + "/ortho");
  EXPECT_EQ(wide.code, 1) << wide.err;
  EXPECT_EQ(lines(wide.err), 1u) << wide.err;
  EXPECT_NE(wide.err.find("ortho.gltf: orthographic camera 0 ymag is 1e+19, beyond the supported 1e+12"), std::string::npos)
      << wide.err;
  EXPECT_FALSE(fs::exists(dir + "/ortho"));
}

TEST(SceneLimits, JsonNested20000DeepIsOneLineNamingTheFileAndTheLimit) {
  const std::string dir = temp_dir("deep");
  const std::string deep = std::string(20000, '[') + std::string(20000, ']');  // 40 KB
  for (const auto& [name, node, top] : {std::tuple<std::string, std::string, std::string>{"top.gltf", "", ",\"extras\":" + deep},
                                        {"node.gltf", ",\"extras\":" + deep, ""}}) {
    const std::string scene = write_scene(dir, name, node, kPerspective, "", top);
    const Result r = run(std::string(kRender) + " --scene " + scene + " --out " + dir + "/out");
    EXPECT_EQ(r.code, 1) << name << ": " << r.err;  // was SIGSEGV: a stack overflow in the JSON conversion
    EXPECT_EQ(lines(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find(scene + ": JSON nested deeper than 256 levels"), std::string::npos) << r.err;
  }
}

TEST(SceneLimits, TextureTransformOf3e38RendersWithAWarning) {
  const std::string dir = temp_dir("transform");
  // A 1x1 white PNG as the base color texture, its transform's offset and scale 3e38.
  const std::string png =
      "iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAIAAACQd1PeAAAADElEQVR42mP4//8/AAX+Av4zEpUUAAAAAElFTkSuQmCC";
  const std::string texture = R"(,"baseColorTexture":{"index":0,"extensions":{"KHR_texture_transform":)"
                              R"({"offset":[3e38,3e38],"scale":[3e38,3e38]}}})";
  const std::string images = R"(,"images":[{"uri":"data:image/png;base64,)" + png + R"("}],"textures":[{"source":0}],)"
                             R"("extensionsUsed":["KHR_texture_transform"])";
  const std::string scene = write_scene(dir, "transform.gltf", "", kPerspective,
                                        texture, images);
  const Result r = run(std::string(kRender) + " --scene " + scene + " --out " + dir + "/out");
  // Was: "buffer 'range_color' has non-finite values (a bug)", exit 1 and no outputs.
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir + "/out/final.exr"));
  EXPECT_NE(messages(r.err).find("texture transform has an offset or scale beyond +-1.68e+07; clamped to it"), std::string::npos)
      << r.err;
}

TEST(SceneLimits, EnvironmentMapOverMaxTextureSizeIsRefusedBeforeDecoding) {
  const std::string dir = temp_dir("env");
  const std::string scene = write_scene(dir, "quad.gltf", "");
  const std::string env = dir + "/env.exr";
  write_exr(env, Image::rgb(64, 32, 1.0f));
  // Was: loaded whatever its size (an 8192x4096 EXR of 207 KB peaked at 1.1 GB under --max-texture-size 16).
  const Result r = run(std::string(kRender) + " --scene " + scene + " --env " + env + " --max-texture-size 16 --out " + dir + "/out");
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_EQ(lines(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find(env + ": environment map is 64x32, over the texture size limit of 16 (raise it with --max-texture-size)"),
            std::string::npos) << r.err;
  const Result raised = run(std::string(kRender) + " --scene " + scene + " --env " + env + " --max-texture-size 64 --out " + dir + "/ok");
  EXPECT_EQ(raised.code, 0) << raised.err;
}

}  // namespace

// A stats.json beside a reference, nested 20,000 deep: pxf diff reads it for --second-reference and
// quotes its settings in errors (dump() recurses), so it is refused in one line before parsing.
TEST(SceneLimits, DeepStatsJsonBesideAReferenceIsOneLine) {
  const std::string dir = temp_dir("deep_stats");
  ASSERT_EQ(run("render --size 16x16 --spp 1 --quiet --out " + dir + "/a").code, 0);
  fs::create_directories(dir + "/b");
  fs::copy_file(dir + "/a/final.exr", dir + "/b/final.exr");  // follows the link: a plain file
  std::ofstream(dir + "/b/stats.json") << "{\"settings\":" << std::string(20000, '[') << std::string(20000, ']') << "}";
  const Result r = run("diff " + dir + "/a/final.exr " + dir + "/a/final.exr --second-reference " + dir + "/b/final.exr");
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_EQ(lines(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find(dir + "/b/stats.json: JSON nested deeper than 256 levels"), std::string::npos) << r.err;
}
