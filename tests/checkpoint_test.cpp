// Checkpoint, resume and shard merging end to end through the pxf executable: a render
// killed with SIGKILL at random moments and resumed gives the uninterrupted render's images bit for
// bit; merges of uneven shards equal one render within the stated tolerance; states of another
// render, overlapping shards and corrupt files are refused with one line and overwrite nothing.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <thread>

#include "image/image.h"
#include "tests/test_support.h"

namespace fs = std::filesystem;
using namespace pxf;

namespace {

const std::string kScene = "--scene cornell --size 40x32 --quiet";
constexpr int kSpp = 24;

std::string temp_dir(const std::string& name) { return test_support::temp_dir("checkpoint", name); }
using test_support::slurp;

struct Result {
  int code = -1;
  std::string err;
};

Result pxf_run(const std::string& args) {
  const std::string err = temp_dir("stderr");
  const std::string cmd = std::string(PXF_EXECUTABLE) + " " + args + " >/dev/null 2>" + err;
  const int status = std::system(cmd.c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(err)};
}

// Starts pxf without a shell so that the pid is pxf's own.
pid_t pxf_spawn(const std::vector<std::string>& args) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    std::vector<char*> argv{const_cast<char*>(PXF_EXECUTABLE)};
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    ::freopen("/dev/null", "w", stdout);
    ::freopen("/dev/null", "w", stderr);
    ::execv(PXF_EXECUTABLE, argv.data());
    ::_exit(127);
  }
  return pid;
}

std::vector<std::string> split(const std::string& text) {
  std::vector<std::string> words;
  std::istringstream in(text);
  for (std::string w; in >> w;) words.push_back(w);
  return words;
}

// Whether every layer is the same, bit for bit; a failure names the layers that differ.
bool same_pixels(const std::vector<Layer>& a, const std::vector<Layer>& b) {
  if (a.size() != b.size()) return false;
  std::string differing;
  for (size_t i = 0; i < a.size(); ++i)
    if (a[i].name != b[i].name || a[i].image.pixels != b[i].image.pixels) differing += " " + a[i].name;
  if (!differing.empty()) ADD_FAILURE() << "layers differ:" << differing;
  return differing.empty();
}

// Every file under an output name is complete: it reads back whole.
void expect_outputs_complete(const std::string& dir) {
  if (fs::exists(dir + "/final.exr")) {
    EXPECT_NO_THROW(read_exr(dir + "/final.exr")) << dir;
  }
  if (fs::exists(dir + "/buffers.exr")) {
    EXPECT_NO_THROW(read_exr_layers(dir + "/buffers.exr")) << dir;
  }
  if (fs::exists(dir + "/final.png")) {
    EXPECT_NO_THROW(read_ldr_or_hdr(dir + "/final.png")) << dir;
  }
  if (fs::exists(dir + "/stats.json")) {
    EXPECT_NO_THROW({
      const nlohmann::json stats = nlohmann::json::parse(slurp(dir + "/stats.json"));
      EXPECT_TRUE(stats.is_object()) << dir;
    }) << dir;
  }
}

using test_support::expect_merge_close;

}  // namespace

namespace {

// `trials` renders of `scene` at kSpp, each killed with SIGKILL at a random moment and resumed
// from its last periodic state (or started again), give the uninterrupted render's images bit for bit.
void expect_resume_after_kills_is_bit_identical(const std::string& scene, const std::string& name, int trials) {
  const std::string ref = temp_dir(name + "_uninterrupted");
  const auto started = std::chrono::steady_clock::now();
  ASSERT_EQ(pxf_run("render " + scene + " --spp " + std::to_string(kSpp) + " --out " + ref).code, 0);
  const int render_ms = static_cast<int>(
      std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - started).count());
  const std::vector<Layer> ref_buffers = read_exr_layers(ref + "/buffers.exr");
  const Image ref_final = read_exr(ref + "/final.exr");

  // The kills span a whole render as long as it takes here (a loaded machine starts pxf slowly:
  // a fixed 1.5 s window then ended before most first checkpoints).
  std::mt19937 rng(13);
  std::uniform_int_distribution<int> kill_after_ms(20, std::max(1500, render_ms));
  int resumed = 0;
  for (int trial = 0; trial < trials; ++trial) {
    SCOPED_TRACE("trial " + std::to_string(trial));
    const std::string out = temp_dir(name + "_killed_" + std::to_string(trial));
    const pid_t pid = pxf_spawn(split("render " + scene + " --spp " + std::to_string(kSpp) +
                                      " --checkpoint 0.05 --out " + out));
    ASSERT_GT(pid, 0);
    std::this_thread::sleep_for(std::chrono::milliseconds(kill_after_ms(rng)));
    ::kill(pid, SIGKILL);
    int status = 0;
    ::waitpid(pid, &status, 0);
    expect_outputs_complete(out);
    const std::string state = out + "/state.pxfs";
    const std::string resume = fs::exists(state) ? " --resume " + state : "";
    resumed += !resume.empty();
    const Result r = pxf_run("render " + scene + " --spp " + std::to_string(kSpp) + resume + " --out " + out);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(same_pixels(read_exr_layers(out + "/buffers.exr"), ref_buffers));
    EXPECT_EQ(read_exr(out + "/final.exr").pixels, ref_final.pixels);
  }
  EXPECT_GE(resumed, trials / 4) << "too few kills landed after the first checkpoint to test resuming";
}

}  // namespace

TEST(Checkpoint, ResumeAfterSigkillAtRandomMomentsIsBitIdentical) {
  expect_resume_after_kills_is_bit_identical(kScene, "uniform", 20);
}

// Adaptive sampling: an adaptive render's state holds each pixel's traced count and the allocation's credits
// and next mask (format 6), and the allocation's guide is the converged range buffer whatever the
// timing, so a resumed adaptive render traces exactly what the uninterrupted one did. 16 warm-up
// frames, then 8 allocated ones.
TEST(Checkpoint, AdaptiveResumeAfterSigkillIsBitIdentical) {
  expect_resume_after_kills_is_bit_identical(kScene + " --adaptive on", "adaptive", 5);
}

// An adaptive shard (--frames A:B or --shard i/n with --adaptive on) is an adaptive render of B - A
// frames whose pixel p takes the sample indices 32 A, 32 A + 1, ... as far as its allocation goes, so
// shards hold disjoint samples and their merge is their exact sum: counts add, means are the
// sample-weighted means. A merged adaptive state is not resumed, and an adaptive and a uniform
// state do not merge.
TEST(Checkpoint, AdaptiveShardsMergeIntoTheirExactSum) {
  const std::string scene = kScene + " --adaptive on";
  std::vector<std::string> dirs;
  std::string states;
  for (const char* shard : {"0/2", "1/2"}) {
    dirs.push_back(temp_dir(std::string("adaptive_shard_") + shard[0]));
    const Result r = pxf_run("render " + scene + " --spp 48 --shard " + shard + " --out " + dirs.back());
    ASSERT_EQ(r.code, 0) << r.err;
    states += " " + dirs.back() + "/state.pxfs";
  }
  const std::string merged_dir = temp_dir("adaptive_merged");
  const Result r = pxf_run("merge" + states + " --scene cornell --out " + merged_dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const std::vector<Layer> merged = read_exr_layers(merged_dir + "/buffers.exr");
  const std::vector<Layer> a = read_exr_layers(dirs[0] + "/buffers.exr"), b = read_exr_layers(dirs[1] + "/buffers.exr");
  const Image& na = layer_image(a, "samples");
  const Image& nb = layer_image(b, "samples");
  const Image& n = layer_image(merged, "samples");
  bool uneven = false;
  for (size_t p = 0; p < n.pixels.size(); ++p) {
    ASSERT_EQ(n.pixels[p], na.pixels[p] + nb.pixels[p]) << p;
    uneven |= na.pixels[p] != na.pixels[0];
    for (const char* layer : {"lv", "hv"})
      for (int c = 0; c < 3; ++c) {
        const float va = layer_image(a, layer).pixels[3 * p + c], vb = layer_image(b, layer).pixels[3 * p + c];
        const float expected = (va * na.pixels[p] + vb * nb.pixels[p]) / n.pixels[p];
        EXPECT_NEAR(layer_image(merged, layer).pixels[3 * p + c], expected, 2e-5f * std::abs(expected) + 1e-6f)
            << layer << " " << p;
      }
  }
  EXPECT_TRUE(uneven) << "the shards' allocation traced every pixel alike: nothing adaptive was merged";
  const nlohmann::json stats = nlohmann::json::parse(slurp(merged_dir + "/stats.json"));
  EXPECT_EQ(stats["settings"]["adaptive"], true);

  const Result resume = pxf_run("render " + scene + " --spp 64 --resume " + merged_dir + "/state.pxfs --out " +
                                temp_dir("adaptive_resumed_merge"));
  EXPECT_EQ(resume.code, 1);
  EXPECT_NE(resume.err.find("do not start this render's frames"), std::string::npos) << resume.err;
  const std::string uniform = temp_dir("uniform_shard");
  ASSERT_EQ(pxf_run("render " + kScene + " --frames 48:50 --out " + uniform).code, 0);
  const Result mixed = pxf_run("merge" + states + " " + uniform + "/state.pxfs --scene cornell --out " +
                               temp_dir("mixed_merge"));
  EXPECT_EQ(mixed.code, 1);
  EXPECT_NE(mixed.err.find("adaptive sampling"), std::string::npos) << mixed.err;
  const Result other = pxf_run("render " + kScene + " --spp 48 --resume " + dirs[0] + "/state.pxfs --out " + dirs[0]);
  EXPECT_EQ(other.code, 1);
  EXPECT_NE(other.err.find("adaptive sampling"), std::string::npos) << other.err;
}

// Shards of an adaptive --until-clean render (the allocation's goal clean, SampleSettings::adaptive
// 2) merge: pxf merge takes the goal back from the states with the other sampling settings
// (apply_sample_settings). It once compared them with goal error and refused.
TEST(Checkpoint, UntilCleanAdaptiveShardsMerge) {
  std::string states;
  for (const char* shard : {"0/2", "1/2"}) {
    const std::string dir = temp_dir(std::string("clean_shard_") + shard[0]);
    const Result r = pxf_run("render " + kScene + " --adaptive on --until-clean --threshold 0.5 --spp 40 --shard " +
                             shard + " --out " + dir);
    ASSERT_EQ(r.code, 0) << r.err;
    states += " " + dir + "/state.pxfs";
  }
  const std::string merged_dir = temp_dir("clean_merged");
  const Result r = pxf_run("merge" + states + " --scene cornell --out " + merged_dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(slurp(merged_dir + "/stats.json"))["settings"]["adaptive"], true);
}

// Path guiding (docs/guiding.md): the state holds the field learned so far, so a resumed guided
// render continues exactly, whatever moment of the field's iterations it was killed at.
TEST(Checkpoint, GuidedResumeAfterSigkillIsBitIdentical) {
  expect_resume_after_kills_is_bit_identical(kScene + " --guiding on", "guided", 3);
}

// --guiding auto (the default) in a room lit through a window starts guiding at the visibility
// field's verdict (frame 4): the state holds both fields, so a render killed before or after that
// frame resumes exactly.
TEST(Checkpoint, AutoGuidedResumeAfterSigkillIsBitIdentical) {
  const std::string window = "--scene window --size 40x32 --quiet";
  const std::string out = temp_dir("auto_guided_probe");
  ASSERT_EQ(pxf_run("render " + window + " --spp 8 --out " + out).code, 0);
  EXPECT_EQ(nlohmann::json::parse(slurp(out + "/stats.json"))["guiding_active"], true);
  expect_resume_after_kills_is_bit_identical(window, "auto_guided", 3);
}

// Guided shards each learn their own field: their merge is the exact sum of their samples, but it
// keeps no field, so it is not resumed.
TEST(Checkpoint, GuidedShardsMergeButAreNotResumed) {
  const std::string scene = kScene + " --guiding on";
  std::vector<std::string> dirs;
  std::string states;
  for (const char* shard : {"0/2", "1/2"}) {
    dirs.push_back(temp_dir(std::string("guided_shard_") + shard[0]));
    const Result r = pxf_run("render " + scene + " --spp 16 --shard " + shard + " --out " + dirs.back());
    ASSERT_EQ(r.code, 0) << r.err;
    states += " " + dirs.back() + "/state.pxfs";
  }
  const std::string merged_dir = temp_dir("guided_merged");
  const Result r = pxf_run("merge" + states + " --scene cornell --out " + merged_dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const std::vector<Layer> merged = read_exr_layers(merged_dir + "/buffers.exr");
  const std::vector<Layer> a = read_exr_layers(dirs[0] + "/buffers.exr"), b = read_exr_layers(dirs[1] + "/buffers.exr");
  const Image& n = layer_image(merged, "samples");
  for (size_t p = 0; p < n.pixels.size(); ++p)
    for (const char* layer : {"lv", "hv"})
      for (int c = 0; c < 3; ++c) {
        const float va = layer_image(a, layer).pixels[3 * p + c], vb = layer_image(b, layer).pixels[3 * p + c];
        const float na = layer_image(a, "samples").pixels[p], nb = layer_image(b, "samples").pixels[p];
        const float expected = (va * na + vb * nb) / n.pixels[p];
        EXPECT_NEAR(layer_image(merged, layer).pixels[3 * p + c], expected, 2e-5f * std::abs(expected) + 1e-6f)
            << layer << " " << p;
      }
  const nlohmann::json stats = nlohmann::json::parse(slurp(merged_dir + "/stats.json"));
  EXPECT_EQ(stats["settings"]["guiding"], "on");
  const Result resume = pxf_run("render " + scene + " --spp 32 --resume " + merged_dir + "/state.pxfs --out " +
                                temp_dir("guided_resumed_merge"));
  EXPECT_EQ(resume.code, 1);
  EXPECT_NE(resume.err.find("no guiding field"), std::string::npos) << resume.err;
  const Result unguided = pxf_run("render " + kScene + " --spp 16 --resume " + dirs[0] + "/state.pxfs --out " +
                                  temp_dir("unguided_resume"));
  EXPECT_EQ(unguided.code, 1);
  EXPECT_NE(unguided.err.find("guiding on vs auto"), std::string::npos) << unguided.err;
}

TEST(Checkpoint, MergeOfUnevenShardsEqualsOneRender) {
  const std::string ref = temp_dir("single");
  ASSERT_EQ(pxf_run("render " + kScene + " --spp " + std::to_string(kSpp) + " --out " + ref).code, 0);
  const std::vector<Layer> single = read_exr_layers(ref + "/buffers.exr");
  for (const std::vector<int>& cuts : {std::vector<int>{0, 17, 24}, {0, 2, 11, 24}, {0, 1, 2, 7, 8, 15, 23, 24}}) {
    const int n = static_cast<int>(cuts.size()) - 1;
    SCOPED_TRACE(std::to_string(n) + " shards");
    std::string states;
    for (int i = 0; i < n; ++i) {
      const std::string dir = temp_dir("shard_" + std::to_string(n) + "_" + std::to_string(i));
      const std::string frames = std::to_string(cuts[i]) + ":" + std::to_string(cuts[i + 1]);
      const Result r = pxf_run("render " + kScene + " --frames " + frames + " --out " + dir);
      ASSERT_EQ(r.code, 0) << r.err;
      states += " " + dir + "/state.pxfs";
    }
    const std::string merged_dir = temp_dir("merged_" + std::to_string(n));
    const Result r = pxf_run("merge" + states + " --scene cornell --out " + merged_dir);
    ASSERT_EQ(r.code, 0) << r.err;
    const std::vector<Layer> merged = read_exr_layers(merged_dir + "/buffers.exr");
    for (const char* layer : {"lv", "hv", "var_u", "samples", "final"})
      expect_merge_close(layer_image(merged, layer), layer_image(single, layer), layer);
  }
}

// Under the split decision the blend reads each pixel's halves, which a merge combines from the
// shards' (docs/method.md 3.8): its image is the one render's, odd cuts (shards that start on an
// odd sample index) included. The odd half's variance is derived by subtraction, and before its
// rounding was snapped to 0 a pixel whose odd samples were all equal flipped its decision between
// the two.
TEST(Checkpoint, SplitDecisionShardsMergeIntoTheOneRender) {
  const std::string split = " --split-decision on";
  const std::string ref = temp_dir("split_single");
  ASSERT_EQ(pxf_run("render " + kScene + split + " --spp " + std::to_string(kSpp) + " --out " + ref).code, 0);
  const std::vector<Layer> single = read_exr_layers(ref + "/buffers.exr");
  const std::vector<int> cuts{0, 5, 11, 24};
  std::string states;
  for (size_t i = 0; i + 1 < cuts.size(); ++i) {
    const std::string dir = temp_dir("split_shard_" + std::to_string(i));
    const std::string frames = std::to_string(cuts[i]) + ":" + std::to_string(cuts[i + 1]);
    const Result r = pxf_run("render " + kScene + split + " --frames " + frames + " --out " + dir);
    ASSERT_EQ(r.code, 0) << r.err;
    states += " " + dir + "/state.pxfs";
  }
  const std::string merged_dir = temp_dir("split_merged");
  const Result r = pxf_run("merge" + states + " --scene cornell" + split + " --out " + merged_dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const std::vector<Layer> merged = read_exr_layers(merged_dir + "/buffers.exr");
  for (const char* layer : {"hv", "blend", "final"})
    expect_merge_close(layer_image(merged, layer), layer_image(single, layer), layer);
}

// With --replicates K > 1 (Var[L_u] from independently scrambled Sobol replicates) the state
// carries the per-replicate sums: a resumed render is bit-identical and a merge of shards that cut
// the replicate cycle equals one render, variance and blended image included.
TEST(Checkpoint, ResumeAndMergeKeepTheReplicateVariance) {
  const std::string scene = kScene + " --replicates 4";
  const std::string ref = temp_dir("replicates_single");
  ASSERT_EQ(pxf_run("render " + scene + " --spp " + std::to_string(kSpp) + " --out " + ref).code, 0);
  const std::vector<Layer> single = read_exr_layers(ref + "/buffers.exr");

  const std::string part = temp_dir("replicates_part");
  ASSERT_EQ(pxf_run("render " + scene + " --spp 9 --checkpoint 100 --out " + part).code, 0);
  const Result resumed = pxf_run("render " + scene + " --spp " + std::to_string(kSpp) + " --resume " + part +
                                 "/state.pxfs --out " + part);
  ASSERT_EQ(resumed.code, 0) << resumed.err;
  EXPECT_TRUE(same_pixels(read_exr_layers(part + "/buffers.exr"), single));

  std::string states;
  for (const char* frames : {"0:9", "9:14", "14:24"}) {
    const std::string dir = temp_dir(std::string("replicates_shard_") + frames);
    const Result r = pxf_run("render " + scene + " --frames " + frames + " --out " + dir);
    ASSERT_EQ(r.code, 0) << r.err;
    states += " " + dir + "/state.pxfs";
  }
  const std::string merged_dir = temp_dir("replicates_merged");
  const Result r = pxf_run("merge" + states + " --scene cornell --out " + merged_dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const std::vector<Layer> merged = read_exr_layers(merged_dir + "/buffers.exr");
  for (const char* layer : {"var_u", "final"})
    expect_merge_close(layer_image(merged, layer), layer_image(single, layer), layer);
}

TEST(Checkpoint, ForeignOverlappingAndCorruptStatesAreRefused) {
  const std::string a = temp_dir("a"), b = temp_dir("b");
  ASSERT_EQ(pxf_run("render " + kScene + " --frames 0:4 --out " + a).code, 0);
  ASSERT_EQ(pxf_run("render " + kScene + " --frames 2:6 --out " + b).code, 0);
  const std::string out = temp_dir("refused");

  const Result overlap = pxf_run("merge " + a + "/state.pxfs " + b + "/state.pxfs --scene cornell --out " + out);
  EXPECT_EQ(overlap.code, 1);
  EXPECT_NE(overlap.err.find("overlap"), std::string::npos) << overlap.err;

  const std::string seed2 = temp_dir("seed2");
  ASSERT_EQ(pxf_run("render " + kScene + " --frames 4:6 --seed 2 --out " + seed2).code, 0);
  const Result mismatch = pxf_run("merge " + a + "/state.pxfs " + seed2 + "/state.pxfs --scene cornell --out " + out);
  EXPECT_EQ(mismatch.code, 1);
  EXPECT_NE(mismatch.err.find("seed"), std::string::npos) << mismatch.err;

  const Result other_scene = pxf_run("merge " + a + "/state.pxfs --scene atrium --out " + out);
  EXPECT_EQ(other_scene.code, 1);
  EXPECT_NE(other_scene.err.find("scene"), std::string::npos) << other_scene.err;

  const std::string bytes = slurp(a + "/state.pxfs");
  const std::string cut = temp_dir("cut.pxfs");
  std::ofstream(cut, std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  const Result corrupt = pxf_run("merge " + cut + " --scene cornell --out " + out);
  EXPECT_EQ(corrupt.code, 1);
  EXPECT_NE(corrupt.err.find("truncated"), std::string::npos) << corrupt.err;

  for (const Result* r : {&overlap, &mismatch, &other_scene, &corrupt})
    EXPECT_EQ(std::count(r->err.begin(), r->err.end(), '\n'), 1) << r->err;
  EXPECT_FALSE(fs::exists(out));

  // Resuming with other settings: refused before anything in the output folder changes.
  const std::string before = slurp(a + "/final.exr");
  const Result resume = pxf_run("render " + kScene + " --spp 8 --max-vertices 4 --resume " + a +
                                "/state.pxfs --out " + a);
  EXPECT_EQ(resume.code, 1);
  EXPECT_NE(resume.err.find("max vertices"), std::string::npos) << resume.err;
  EXPECT_EQ(slurp(a + "/final.exr"), before);
  // The sampler's settings decide the samples too.
  for (const char* flag : {"--sampler independent", "--specular-sampling", "--replicates 4"}) {
    const Result other = pxf_run("render " + kScene + " --spp 8 " + flag + " --resume " + a + "/state.pxfs --out " + a);
    EXPECT_EQ(other.code, 1) << flag;
    EXPECT_NE(other.err.find(std::string(flag).substr(2, 7)), std::string::npos) << other.err;
    EXPECT_EQ(slurp(a + "/final.exr"), before);
  }
}
