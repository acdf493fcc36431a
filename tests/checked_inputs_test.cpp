// Inputs that used to hang, mislead or be accepted, end to end through `pxf`: --until-clean where
// nothing needs the filter, a crafted stats.json beside a diff argument, a reference with NaN
// samples for pxf bench, and emission too bright to represent. pxf runs under `timeout 120`, so
// that a regression (a render that never ends) fails instead of hanging; no test asserts a time.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

#include <nlohmann/json.hpp>

#include "image/image.h"
#include "tests/test_support.h"

namespace fs = std::filesystem;
using namespace pxf;

namespace {

struct Result {
  int code = -1;
  std::string out, err;
};

// pxf with `args`, run in `dir`, stopped after 120 s (exit code 124).
Result run_in(const std::string& dir, const std::string& args) {
  const std::string cmd = "cd '" + dir + "' && timeout 120 " + std::string(PXF_EXECUTABLE) + " " + args +
                          " >out.txt 2>err.txt";
  const int status = std::system(cmd.c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, test_support::slurp(dir + "/out.txt"),
          test_support::slurp(dir + "/err.txt")};
}

size_t lines(const std::string& text) { return std::count(text.begin(), text.end(), '\n'); }

std::string folder(const std::string& name) {
  const std::string dir = test_support::temp_dir("checked_inputs", name);
  fs::create_directories(dir);
  return dir;
}

// One triangle in the z = 0 plane lit by a sun straight down -z onto its front: a fixed light, whose
// light at the first surface is exact (LV), and nothing else to bounce off: HV stays 0.
std::string write_sunlit_triangle(const std::string& dir) {
  const std::string path = dir + "/sunlit.gltf";
  std::ofstream(path) << R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0,1]}],"nodes":[{"mesh":0},)"
                         R"({"extensions":{"KHR_lights_punctual":{"light":0}}}],)"
                         R"("extensionsUsed":["KHR_lights_punctual"],)"
                         R"("extensions":{"KHR_lights_punctual":{"lights":[{"type":"directional","intensity":2}]}},)"
                         R"("meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],)"
                         R"("accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}],)"
                         R"("bufferViews":[{"buffer":0,"byteLength":36}],)"
                         R"("buffers":[{"byteLength":36,"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}]})";
  return path;
}

}  // namespace

// --until-clean where the filter has nothing to do (a black scene; one triangle lit by a sun, whose
// light is exact and has no HV): clean at the first check, not 2^24 frames later.
TEST(CheckedInputs, UntilCleanEndsAtOnceWhereNothingNeedsTheFilter) {
  const std::string dir = folder("until_clean");
  test_support::write_bare_triangle(dir, "triangle.gltf");
  write_sunlit_triangle(dir);
  for (const std::string scene : {"triangle.gltf --default-light none", "sunlit.gltf"}) {
    const Result r = run_in(dir, "render --scene " + scene + " --size 16x16 --until-clean --quiet --out out");
    ASSERT_EQ(r.code, 0) << scene << " (124: it never ended): " << r.err;
    const auto stats = nlohmann::json::parse(test_support::slurp(dir + "/out/stats.json"));
    EXPECT_TRUE(stats["clean"].get<bool>()) << scene;
    EXPECT_TRUE(stats["until_clean"]["time_to_clean_ms"].is_number()) << scene;
    EXPECT_LE(stats["settings"]["spp"].get<int>(), 16) << scene << ": not at the first check";
    EXPECT_NE(r.out.find("until-clean: clean at"), std::string::npos) << r.out;
  }
  // A threshold of 0 can never be clean: a flag error, not a render that never ends.
  const Result zero = run_in(dir, "render --scene triangle.gltf --size 16x16 --until-clean --threshold 0 --out zero");
  EXPECT_EQ(zero.code, 2) << zero.err;
  EXPECT_EQ(lines(zero.err), 1u) << zero.err;
  EXPECT_NE(zero.err.find("--threshold"), std::string::npos) << zero.err;
}

// stats.json beside a diff argument goes through one checked reader: a wrong type or an out-of-range
// value is one line naming the file (it was "internal error: [json.exception.type_error...]", or
// accepted: spp 1e300, threshold -1).
TEST(CheckedInputs, DiffRefusesACraftedStatsJsonNamingIt) {
  const std::string dir = folder("stats_json");
  fs::create_directories(dir + "/a");
  fs::create_directories(dir + "/b");
  write_exr(dir + "/test.exr", Image::rgb(4, 4, 0.5f));
  write_exr(dir + "/a/final.exr", Image::rgb(4, 4, 0.5f));
  write_exr(dir + "/b/final.exr", Image::rgb(4, 4, 0.5f));
  std::ofstream(dir + "/b/stats.json") << R"({"settings": {"scene": "cornell", "width": 4, "height": 4, "spp": 8, "seed": 2}})";
  const std::string good = R"({"settings": {"scene": "cornell", "width": 4, "height": 4, "spp": 8, "seed": 1}})";
  std::ofstream(dir + "/a/stats.json") << good;
  const Result fine = run_in(dir, "diff test.exr a/final.exr --second-reference b/final.exr");
  ASSERT_EQ(fine.code, 0) << fine.err;
  for (const std::string crafted :
       {R"({"settings": 5})", R"({"settings": {"spp": "x", "seed": 1}})",
        R"({"settings": {"seed": 1}, "time_budget": {"spp_reached": "x"}})", R"({"settings": {"spp": 1e300, "seed": 1}})",
        R"({"settings": {"threshold": -1, "seed": 1}})", R"({"settings": {"seed": "1"}})", R"([1, 2])",
        R"({"settings": {"width": 4.5, "seed": 1}})"}) {
    std::ofstream(dir + "/a/stats.json") << crafted;
    const Result r = run_in(dir, "diff test.exr a/final.exr --second-reference b/final.exr");
    EXPECT_EQ(r.code, 1) << crafted << ": " << r.err;
    EXPECT_EQ(lines(r.err), 1u) << crafted << ": " << r.err;
    EXPECT_NE(r.err.find("a/stats.json: "), std::string::npos) << crafted << ": " << r.err;
    EXPECT_EQ(r.err.find("internal error"), std::string::npos) << crafted << ": " << r.err;
  }
}

// pxf bench --reference checks its reference exactly as pxf diff does: NaN samples are refused with
// the same line (they were used, and NRMSE figures reported with exit 0).
TEST(CheckedInputs, BenchRefusesAReferenceWithNaNSamplesLikeDiff) {
  const std::string dir = folder("bench_reference");
  Image nan = Image::rgb(16, 16, 0.5f);
  nan.at(3, 4, 1) = std::numeric_limits<float>::quiet_NaN();
  write_exr(dir + "/nan.exr", nan);
  write_exr(dir + "/test.exr", Image::rgb(16, 16, 0.5f));
  const Result diff = run_in(dir, "diff test.exr nan.exr");
  test_support::write_bare_triangle(dir, "triangle.gltf");
  const Result bench = run_in(dir, "bench demodulation-ab --scene triangle.gltf --size 16x16 --budgets 1 --rounds 1 --reference nan.exr --out b");
  const std::string line = "nan.exr: 1 non-finite samples (NaN or Inf); it cannot serve as a reference";
  for (const Result* r : {&diff, &bench}) {
    EXPECT_EQ(r->code, 1) << r->err;
    EXPECT_NE(r->err.find(line), std::string::npos) << r->err;
  }
}
