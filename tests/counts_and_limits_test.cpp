// Counts and limits end to end through the pxf executable (near-misses included):
// frame counts are checked at the command line and in states with one line; a size whose grid
// filter needs more work groups than one dispatch row holds still renders; --time refuses up front
// when not even one frame fits; a failed periodic state write warns once and the render goes on.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "tests/test_support.h"

namespace fs = std::filesystem;
using namespace pxf;

namespace {

std::string temp_dir(const std::string& name) { return test_support::temp_dir("counts_and_limits", name); }
using test_support::slurp;

struct Result {
  int code = -1;
  std::string out, err;
};

Result pxf_run(const std::string& args) {
  const std::string dir = temp_dir("streams");
  fs::create_directories(dir);
  const std::string cmd =
      std::string(PXF_EXECUTABLE) + " " + args + " >" + dir + "/stdout 2>" + dir + "/stderr";
  const int status = std::system(cmd.c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(dir + "/stdout"), slurp(dir + "/stderr")};
}

size_t lines(const std::string& text) { return static_cast<size_t>(std::count(text.begin(), text.end(), '\n')); }

bool has_outputs(const std::string& dir) {
  for (const char* name : {"final.png", "final.exr", "buffers.exr", "stats.json"})
    if (!fs::is_regular_file(dir + "/" + name)) return false;
  return true;
}

// The crafted state of the fuzz corpus: 2x1 pixels, one range of 2^31 frames, valid checksum.
const std::string kTwoTo31FramesState = std::string(PXF_SOURCE_DIR) + "/fuzz/corpus/state_reader/frames_2pow31.pxfs";

TEST(CountsAndLimits, FramesOf2To31OrMoreAreRefusedAtTheCommandLine) {
  for (const char* range : {"0:4294967295", "0:2147483648", "0:16777217"}) {
    const std::string out = temp_dir("frames");
    const Result r = pxf_run(std::string("render --size 16x16 --quiet --frames ") + range + " --out " + out);
    EXPECT_EQ(r.code, 2) << range << ": " << r.err;
    EXPECT_EQ(lines(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find("16777216"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out)) << range;
    EXPECT_EQ(r.out.find("wrote"), std::string::npos) << r.out;  // no claim of a state not written
  }
}

TEST(CountsAndLimits, AStateOf2To31FramesIsRefusedWithOneLine) {
  ASSERT_TRUE(fs::is_regular_file(kTwoTo31FramesState));
  const std::string out = temp_dir("merge");
  const Result r = pxf_run("merge " + kTwoTo31FramesState + " --scene cornell --out " + out);
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_EQ(lines(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find("2147483648 frames"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out + "/stats.json"));
  const Result resume = pxf_run("render --size 2x1 --quiet --resume " + kTwoTo31FramesState + " --out " + out);
  EXPECT_EQ(resume.code, 1) << resume.err;
  EXPECT_EQ(lines(resume.err), 1u) << resume.err;
}

// 16384x100 at sigma_s 0.1: the grid's blur needs 66,578 work groups (4097 x 26 x 40 cells / 64),
// more than GL_MAX_COMPUTE_WORK_GROUP_COUNT's 65,535 on llvmpipe: "filter pass: GL error 0x0501"
// after the tracing, and no outputs, before the dispatch was laid out in rows.
TEST(CountsAndLimits, GridFilterOverMoreThan65535WorkGroupsRenders) {
  const std::string out = temp_dir("wide");
  const Result r = pxf_run("render --size 16384x100 --sigma-s 0.1 --schedule every --spp 1 --quiet --out " + out);
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(has_outputs(out)) << r.err;
  const nlohmann::json stats = nlohmann::json::parse(slurp(out + "/stats.json"));
  EXPECT_EQ(stats["settings"]["spp"], 1);
}

// --time 0.001 cannot hold one frame at 512x512 (four times the probe's pixels): refused up front
// with one line and exit 1, nothing written, instead of tracing the first frame regardless.
TEST(CountsAndLimits, RefusedUpFrontWhenNotEvenOneFrameFits) {
  const std::string out = temp_dir("time");
  const Result r = pxf_run("render --size 512x512 --time 0.001 --out " + out);
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_EQ(lines(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find("--time"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("512x512"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out + "/stats.json"));
  // A small image still traces its first frame (no probe: it costs about what a probe would).
  const std::string small = temp_dir("time_small");
  const Result s = pxf_run("render --size 16x16 --time 0.001 --out " + small);
  EXPECT_EQ(s.code, 0) << s.err;
  EXPECT_TRUE(has_outputs(small));
}

// The state's name is taken by a folder, so every state write fails (as on a full disk). Periodic
// writes warn once and the render goes on to its last frame; the final write's failure gives exit
// 1, after the outputs are written.
TEST(CountsAndLimits, AFailedPeriodicWriteWarnsOnceAndTheRenderGoesOn) {
  const std::string out = temp_dir("checkpoint");
  fs::create_directories(out + "/state.pxfs/occupied");
  const Result r = pxf_run("render --size 16x16 --spp 6 --quiet --checkpoint 0.000001 --out " + out);
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_TRUE(has_outputs(out)) << r.err;
  const nlohmann::json stats = nlohmann::json::parse(slurp(out + "/stats.json"));
  EXPECT_EQ(stats["settings"]["spp"], 6);
  EXPECT_EQ(lines(r.err), 2u) << r.err;  // the one warning and the final write's error
  EXPECT_NE(r.err.find("warning"), std::string::npos) << r.err;
  EXPECT_EQ(r.out.find("state.pxfs"), std::string::npos) << r.out;  // not claimed as written
  EXPECT_TRUE(fs::is_directory(out + "/state.pxfs/occupied"));
}

}  // namespace
