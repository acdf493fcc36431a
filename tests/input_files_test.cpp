// Every input path pxf reads is checked to be a regular file of bounded size before it is opened
// (image/input_file.h): a FIFO, /dev/zero or a directory named as any
// input ends the command with exit code 1 and one line naming the path, at once. pxf runs under
// `timeout 20`, so that a regression (a read that blocks or never ends) fails instead of hanging.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "image/image.h"
#include "tests/test_support.h"

namespace fs = std::filesystem;
using namespace pxf;

namespace {

struct Result {
  int code = -1;
  std::string err;
};

// pxf with `args`, run in `dir`, stopped after 20 s (exit code 124: it blocked or read on and on).
Result run_in(const std::string& dir, const std::string& args) {
  const std::string cmd = "cd '" + dir + "' && timeout 20 " + std::string(PXF_EXECUTABLE) + " " + args +
                          " >out.txt 2>err.txt";
  const int status = std::system(cmd.c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, test_support::slurp(dir + "/err.txt")};
}

size_t lines(const std::string& text) { return std::count(text.begin(), text.end(), '\n'); }

// The refusal every case expects: exit code 1 and one line on stderr naming `path` and `problem`.
void expect_refused(const Result& r, const std::string& path, const std::string& problem) {
  EXPECT_EQ(r.code, 1) << "124 means it blocked or never stopped reading; stderr: " << r.err;
  EXPECT_EQ(lines(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find(path + ": " + problem), std::string::npos) << r.err;
}

// A fresh folder for one test.
std::string folder(const std::string& name) {
  const std::string dir = test_support::temp_dir("input_files", name);
  fs::create_directories(dir);
  return dir;
}

void make_fifo(const std::string& path) { ASSERT_EQ(::mkfifo(path.c_str(), 0600), 0) << path; }

// A small valid RGB EXR, for the argument that is not under test.
void write_image(const std::string& path) { write_exr(path, Image::rgb(4, 4, 0.5f)); }

// A one-triangle glTF (its buffer embedded as a data uri unless `buffer_uri` names one) with the
// given "images" uri, if any: tinygltf reads every image while it parses.
void write_gltf(const std::string& path, const std::string& image_uri, const std::string& buffer_uri = "") {
  // 9 floats: (0,0,0), (1,0,0), (0,1,0).
  const std::string embedded =
      "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA";
  std::ofstream out(path);
  out << R"({"asset":{"version":"2.0"},"buffers":[{"uri":")" << (buffer_uri.empty() ? embedded : buffer_uri)
      << R"(","byteLength":36}],"bufferViews":[{"buffer":0,"byteLength":36}],)"
      << R"("accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}],)"
      << R"("meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],"nodes":[{"mesh":0}],)"
      << R"("scenes":[{"nodes":[0]}],"scene":0)";
  if (!image_uri.empty()) out << R"(,"images":[{"uri":")" << image_uri << R"("}])";
  out << "}\n";
}

const std::string kRender = "render --size 16x16 --spp 1 --out out";
const std::string kFifo = "not a regular file (a FIFO)";
const std::string kCharacterDevice = "not a regular file (a character device)";

}  // namespace

// -- a FIFO as each input: each used to block forever in open() ------------------------------

TEST(InputFiles, FifoAsGltfImageUri) {
  const std::string dir = folder("fifo_image_uri");
  make_fifo(dir + "/texture.png");
  write_gltf(dir + "/scene.gltf", "texture.png");
  expect_refused(run_in(dir, kRender + " --scene scene.gltf"), "texture.png", kFifo);
}

TEST(InputFiles, FifoAsGltfBufferUri) {
  const std::string dir = folder("fifo_buffer_uri");
  make_fifo(dir + "/mesh.bin");
  write_gltf(dir + "/scene.gltf", "", "mesh.bin");
  expect_refused(run_in(dir, kRender + " --scene scene.gltf"), "mesh.bin", kFifo);
}

TEST(InputFiles, FifoAsScene) {
  const std::string dir = folder("fifo_scene");
  make_fifo(dir + "/scene.gltf");
  expect_refused(run_in(dir, kRender + " --scene scene.gltf"), "scene.gltf", kFifo);
}

TEST(InputFiles, FifoAsEnv) {
  const std::string dir = folder("fifo_env");
  make_fifo(dir + "/sky.exr");
  expect_refused(run_in(dir, kRender + " --scene cornell --env sky.exr"), "sky.exr", kFifo);
}

TEST(InputFiles, FifoAsReference) {
  const std::string dir = folder("fifo_reference");
  make_fifo(dir + "/ref.exr");
  expect_refused(run_in(dir, kRender + " --scene cornell --reference ref.exr"), "ref.exr", kFifo);
}

TEST(InputFiles, FifoAsResume) {
  const std::string dir = folder("fifo_resume");
  make_fifo(dir + "/state.pxfs");
  expect_refused(run_in(dir, kRender + " --scene cornell --resume state.pxfs"), "state.pxfs", kFifo);
}

TEST(InputFiles, FifoAsMergeState) {
  const std::string dir = folder("fifo_merge");
  make_fifo(dir + "/state.pxfs");
  expect_refused(run_in(dir, "merge state.pxfs --scene cornell --out out"), "state.pxfs", kFifo);
}

TEST(InputFiles, FifoAsDiffTest) {
  const std::string dir = folder("fifo_diff_test");
  make_fifo(dir + "/test.exr");
  write_image(dir + "/ref.exr");
  expect_refused(run_in(dir, "diff test.exr ref.exr"), "test.exr", kFifo);
}

TEST(InputFiles, FifoAsDiffReference) {
  const std::string dir = folder("fifo_diff_reference");
  write_image(dir + "/test.exr");
  make_fifo(dir + "/ref.exr");
  expect_refused(run_in(dir, "diff test.exr ref.exr"), "ref.exr", kFifo);
}

TEST(InputFiles, FifoAsMask) {
  const std::string dir = folder("fifo_mask");
  write_image(dir + "/test.exr");
  write_image(dir + "/ref.exr");
  make_fifo(dir + "/mask.exr");
  expect_refused(run_in(dir, "diff test.exr ref.exr --mask mask.exr"), "mask.exr", kFifo);
}

// The stats.json beside a reference, read for --second-reference: not named, but read all the same.
TEST(InputFiles, FifoAsStatsJsonBesideDiffReference) {
  const std::string dir = folder("fifo_stats_json");
  fs::create_directories(dir + "/a");
  fs::create_directories(dir + "/b");
  write_image(dir + "/test.exr");
  write_image(dir + "/a/final.exr");
  write_image(dir + "/b/final.exr");
  make_fifo(dir + "/a/stats.json");
  expect_refused(run_in(dir, "diff test.exr a/final.exr --second-reference b/final.exr"), "a/stats.json", kFifo);
}

// -- /dev/zero: a character device that never ends (it used to be read until memory ran out) --

TEST(InputFiles, FifoAsCameraPath) {
  const std::string dir = folder("fifo_camera_path");
  make_fifo(dir + "/path.json");
  expect_refused(run_in(dir, "render --size 16x16 --camera-path path.json --out out"), "path.json", kFifo);
}

TEST(InputFiles, DevZeroAsCameraPath) {
  const std::string dir = folder("zero_camera_path");
  expect_refused(run_in(dir, "render --size 16x16 --camera-path /dev/zero --out out"), "/dev/zero", kCharacterDevice);
}

TEST(InputFiles, DevZeroAsDiffTest) {
  const std::string dir = folder("zero_diff");
  write_image(dir + "/ref.exr");
  expect_refused(run_in(dir, "diff /dev/zero ref.exr"), "/dev/zero", kCharacterDevice);
}

TEST(InputFiles, DevZeroAsReference) {
  const std::string dir = folder("zero_reference");
  expect_refused(run_in(dir, kRender + " --scene cornell --reference /dev/zero"), "/dev/zero", kCharacterDevice);
}

// -- a directory: named in the message, not "basic_filebuf::underflow" or "std::bad_alloc" -----

TEST(InputFiles, DirectoryAsDiffTest) {
  const std::string dir = folder("directory_diff");
  fs::create_directories(dir + "/images");
  write_image(dir + "/ref.exr");
  expect_refused(run_in(dir, "diff images ref.exr"), "images", "is a directory");
}

TEST(InputFiles, DirectoryAsGltfImageUri) {
  const std::string dir = folder("directory_image_uri");
  fs::create_directories(dir + "/texture.png");
  write_gltf(dir + "/scene.gltf", "texture.png");
  expect_refused(run_in(dir, kRender + " --scene scene.gltf"), "texture.png", "is a directory");
}
