// `pxf render --camera-path` end to end: a frame sequence, the same bit for bit with one thread and
// with two, one-line refusals of bad flags and files.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "image/image.h"
#include "tests/test_support.h"

namespace fs = std::filesystem;
using namespace pxf;

namespace {

using Result = test_support::PxfResult;
Result run(const std::string& args) { return test_support::run_pxf(args, "camera_path"); }

std::string write_path_file(const std::string& text) {
  const std::string dir = test_support::temp_dir("camera_path", "files");
  fs::create_directories(dir);
  const std::string file = dir + "/path.json";
  std::ofstream(file) << text;
  return file;
}

TEST(CameraPathCli, RendersTheSameFramesWithOneThreadAndWithTwo) {
  const std::string file = write_path_file(R"({"interpolation": "spline", "keyframes": [
    {"position": [0.15, 0.5, 1.9], "target": [0, 0.5, 0], "frames": 1},
    {"position": [0, 0.52, 1.95], "target": [0, 0.5, 0], "frames": 1},
    {"position": [-0.15, 0.55, 1.9], "target": [0, 0.5, 0]}]})");
  std::vector<std::string> frames[2];  // the PNG files' bytes
  for (int threads = 1; threads <= 2; ++threads) {
    const std::string out = test_support::temp_dir("camera_path", "threads" + std::to_string(threads));
    const Result r = run("render --size 16x16 --camera-path " + file + " --spp-per-frame 2 --quiet --threads " +
                         std::to_string(threads) + " --out " + out);
    ASSERT_EQ(r.code, 0) << r.err;
    const auto stats = nlohmann::json::parse(test_support::slurp(out + "/path.json"));
    ASSERT_EQ(stats["frames"].size(), 3u);
    EXPECT_FALSE(stats["frames"][0]["history"].get<bool>());
    EXPECT_TRUE(stats["frames"][1]["history"].get<bool>());
    for (int f = 0; f < 3; ++f) frames[threads - 1].push_back(test_support::slurp(out + "/frame-000" + std::to_string(f) + ".png"));
  }
  for (int f = 0; f < 3; ++f) EXPECT_EQ(frames[0][f], frames[1][f]) << "frame " << f;
  EXPECT_NE(frames[0][0], frames[0][2]);  // the camera moved
}

TEST(CameraPathCli, ATurntableIsOneCommand) {
  const std::string out = test_support::temp_dir("camera_path", "turntable");
  const Result r = run("render --size 16x16 --camera-path turntable:3 --quiet --out " + out);
  ASSERT_EQ(r.code, 0) << r.err;
  for (int f = 0; f < 3; ++f) EXPECT_TRUE(fs::exists(out + "/frame-000" + std::to_string(f) + ".png")) << f;
  EXPECT_FALSE(fs::exists(out + "/frame-0003.png"));
}

void expect_one_line_refusal(const std::string& args, const std::string& expected) {
  const std::string out = test_support::temp_dir("camera_path", "refused");
  const Result r = run(args + " --out " + out);
  EXPECT_NE(r.code, 0) << args;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find(expected), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out + "/frame-0000.png")) << args;
}

// A bad turntable count is a bad flag value: exit 2, like every other.
TEST(CameraPathCli, ABadTurntableCountIsAUsageError) {
  for (const char* spec : {"turntable:0", "turntable:x", "turntable:-3", "turntable:100001"}) {
    const Result r = run(std::string("render --size 16x16 --camera-path ") + spec + " --out " +
                         test_support::temp_dir("camera_path", "turntable_count"));
    EXPECT_EQ(r.code, 2) << spec << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
}

TEST(CameraPathCli, BadFlagsAndFilesAreRefusedWithOneLine) {
  expect_one_line_refusal("render --size 16x16 --spp-per-frame 2", "needs --camera-path");
  expect_one_line_refusal("render --size 16x16 --camera-path turntable:2 --spp 4", "does not go with --camera-path");
  expect_one_line_refusal("render --size 16x16 --camera-path turntable:x", "turntable:N");
  expect_one_line_refusal("render --size 16x16 --camera-path " + write_path_file("{\"keyframes\": ["), "not valid JSON");
  expect_one_line_refusal("render --size 16x16 --camera-path /nonexistent.json", "no such file");
  expect_one_line_refusal("render --size 16x16 --camera-path " + write_path_file(std::string(300, '[')), "nested deeper");
  expect_one_line_refusal("render --size 16x16 --camera-path " + write_path_file(R"({"keyframes": [
    {"position": [0.5,0.5,2], "target": [0.5,0.5,0], "frames": 2}, {"position": [0.5,0.5,0], "target": [0.5,0.5,2]}]})"),
                          "frame 1: position and target meet");
  expect_one_line_refusal("bench motion --size 16x16 --camera-path " + write_path_file("{\"keyframes\": ["),
                          "not valid JSON");
}

// pxf bench motion measures a camera path's views (one reference per frame, cached by the path's name).
TEST(CameraPathCli, MotionBenchFollowsThePath) {
  const std::string out = test_support::temp_dir("camera_path", "motion_bench");
  const Result r = run("bench motion --one-reference --size 16x16 --camera-path turntable:3 --reference-spp 2 --out " + out);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("camera path turntable:3 (3 frames)"), std::string::npos) << r.out;
  const std::string text = test_support::slurp(out + "/motion.csv");
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 4) << text;  // the header and three frames
  EXPECT_TRUE(fs::exists(out + "/motion_reference_cornell_16x16_path-turntable:3_3f_2spp/reference_0002.exr"));
}

}  // namespace
