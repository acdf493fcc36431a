// The output set end to end: pxf keeps the user's files, and a stop signal, a kill or a second
// render at any moment of the output write leaves the old set or the new one, whole, never neither
// and never a mix; a reader that closes the pipe does not kill the render.
// PXF_STRESS_TRIALS (default 70) and PXF_STRESS_PAIRS (default 35) set the trial counts; the
// figures in docs/notebook/reference-notes.md ("Output set stress runs") were taken with 1000 and 200.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <set>
#include <thread>

#include "app/output_set.h"
#include "image/image.h"
#include "tests/test_support.h"

namespace fs = std::filesystem;
using namespace pxf;

namespace {

const char* const kOutputs[] = {"final.png", "final.exr", "buffers.exr", "stats.json"};
using Clock = std::chrono::steady_clock;

int env_count(const char* name, int fallback) {
  const char* v = std::getenv(name);
  return v && std::atoi(v) > 0 ? std::atoi(v) : fallback;
}

// A render of WIDTHx16 into `out`, as a child process with its output thrown away.
pid_t start_render(const std::string& out, int width, int spp = 1) {
  const std::string size = std::to_string(width) + "x16", samples = std::to_string(spp);
  const pid_t pid = fork();
  if (pid == 0) {
    std::freopen("/dev/null", "w", stderr);
    std::freopen("/dev/null", "w", stdout);
    execl(PXF_EXECUTABLE, "pxf", "render", "--size", size.c_str(), "--spp", samples.c_str(), "--quiet", "--out",
          out.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  return pid;
}

int wait_status(pid_t pid) {
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  return status;
}

// The width that every output of `out` shows, or an error naming what is missing, partial or mixed.
struct SetCheck {
  int width = 0;
  std::string problem;
};

SetCheck check_set(const std::string& out) {
  std::set<int> widths;
  for (const char* name : kOutputs) {
    const std::string path = out + "/" + name;
    if (!fs::exists(path)) return {0, std::string(name) + " is missing"};
    try {
      if (std::string(name) == "stats.json") {
        const auto stats = nlohmann::json::parse(test_support::slurp(path), nullptr, false);
        if (stats.is_discarded()) return {0, "stats.json is not whole"};
        widths.insert(stats["settings"]["width"].get<int>());
      } else if (std::string(name) == "final.png") {
        widths.insert(read_ldr_or_hdr(path).width);
      } else {
        widths.insert(read_exr_layers(path).front().image.width);  // throws on a truncated file
      }
    } catch (const std::exception& e) {
      return {0, std::string(name) + " is not whole: " + e.what()};
    }
  }
  if (widths.size() != 1) return {0, "a mix of two runs"};
  return {*widths.begin(), ""};
}

// The folder the child writes its set into: it appears when its output write begins.
std::string write_marker(pid_t pid) { return set_folder_name(pid, 0); }

// Waits until the child's output write has begun; false if it exited first.
bool wait_for_write(pid_t pid, const std::string& out) {
  const std::string marker = out + "/" + write_marker(pid);
  for (;;) {
    if (access(marker.c_str(), F_OK) == 0) return true;
    int status = 0;
    if (waitpid(pid, &status, WNOHANG) == pid) return false;
    std::this_thread::sleep_for(std::chrono::microseconds(20));
  }
}

// Microseconds from the start of a write into `out` until its set is the current one.
int measure_write_us(const std::string& out) {
  const pid_t pid = start_render(out, 16);
  if (!wait_for_write(pid, out)) return 0;
  const auto began = Clock::now();
  const std::string link = out + "/" + kCurrentSetLink;
  int status = 0;
  while ((!fs::is_symlink(link) || fs::read_symlink(link).string() != set_folder_name(pid, 0)) &&
         waitpid(pid, &status, WNOHANG) != pid)
    std::this_thread::sleep_for(std::chrono::microseconds(20));
  const int us = static_cast<int>(std::chrono::duration_cast<std::chrono::microseconds>(Clock::now() - began).count());
  kill(pid, SIGKILL);  // gone already, or past its commit
  waitpid(pid, &status, 0);
  return us;
}

// What pxf leaves in an output folder besides the outputs: the current-set link and one set folder.
std::vector<std::string> leftovers(const std::string& out) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(out)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(".pxf-", 0) == 0 && name != kCurrentSetLink) names.push_back(name);
  }
  if (names.size() == 1 && fs::read_symlink(out + "/" + kCurrentSetLink).string() == names.front()) names.clear();
  return names;
}

}  // namespace

TEST(OutputSet, UserFilesNamedLikeTemporariesAreKept) {
  const std::string out = test_support::temp_dir("output_set", "user_files");
  fs::create_directories(out + "/thesis.tmp-99999");
  std::ofstream(out + "/thesis.tmp-99999/chapter1.tex") << "chapter one";
  std::ofstream(out + "/report.docx.tmp-4000001") << "report";
  std::ofstream(out + "/final.png.tmp-notapid") << "mine";
  ASSERT_EQ(WEXITSTATUS(wait_status(start_render(out, 16))), 0);
  EXPECT_EQ(test_support::slurp(out + "/thesis.tmp-99999/chapter1.tex"), "chapter one");
  EXPECT_EQ(test_support::slurp(out + "/report.docx.tmp-4000001"), "report");
  EXPECT_EQ(test_support::slurp(out + "/final.png.tmp-notapid"), "mine");
  EXPECT_EQ(check_set(out).problem, "");
}

// Stop signals and kills at random moments of the write, into a folder that holds a complete set
// of another size: afterwards the folder shows one whole set, the old or the new.
TEST(OutputSet, SignalsDuringTheWriteLeaveOneWholeSet) {
  const std::string out = test_support::temp_dir("output_set", "signals");
  ASSERT_EQ(WEXITSTATUS(wait_status(start_render(out, 24))), 0);
  // How long the write takes here: the random moments span it and a little past its commit.
  const int measured_us = measure_write_us(out);
  ASSERT_GT(measured_us, 0) << "the probe render ended before its write";
  const int write_us = std::max(200, measured_us * 5 / 4);

  const int trials = env_count("PXF_STRESS_TRIALS", 70);
  const int kinds[][2] = {{SIGTERM, 0}, {SIGINT, 0}, {SIGKILL, 0}, {SIGINT, SIGINT}, {SIGHUP, 0}};
  std::mt19937 rng(38);
  std::map<std::string, int> outcomes;
  int previous_width = 16;
  for (int trial = 0; trial < trials; ++trial) {
    const int width = previous_width == 16 ? 20 : 16;
    const int* kind = kinds[trial % std::size(kinds)];
    const pid_t pid = start_render(out, width);
    ASSERT_GT(pid, 0);
    const bool writing = wait_for_write(pid, out);
    if (writing) {
      std::this_thread::sleep_for(std::chrono::microseconds(std::uniform_int_distribution<int>(0, write_us)(rng)));
      kill(pid, kind[0]);
      if (kind[1]) {
        std::this_thread::sleep_for(std::chrono::microseconds(std::uniform_int_distribution<int>(0, 300)(rng)));
        kill(pid, kind[1]);
      }
    }
    wait_status(pid);
    const SetCheck set = check_set(out);
    ASSERT_EQ(set.problem, "") << "trial " << trial << ", signal " << kind[0] << (kind[1] ? " twice" : "");
    ASSERT_TRUE(set.width == width || set.width == previous_width) << "trial " << trial;
    ++outcomes[!writing ? "finished before the signal" : set.width == width ? "new set" : "old set"];
    previous_width = set.width;
  }
  // The test means nothing unless the signals met the write.
  EXPECT_GE(trials - outcomes["finished before the signal"], trials * 9 / 10);
  std::string summary;
  for (const auto& [outcome, count] : outcomes) summary += outcome + ": " + std::to_string(count) + "  ";
  std::printf("%d trials over a write of %d us: %s\n", trials, write_us, summary.c_str());
  RecordProperty("outcomes", summary);
  ASSERT_EQ(WEXITSTATUS(wait_status(start_render(out, 16))), 0);
  EXPECT_TRUE(leftovers(out).empty()) << leftovers(out).front();
}

// Two renders of different sizes into one folder at once: both succeed, and the folder shows the
// set of one of them, whole.
TEST(OutputSet, ConcurrentRendersIntoOneFolderNeverMix) {
  const std::string out = test_support::temp_dir("output_set", "pairs");
  const int pairs = env_count("PXF_STRESS_PAIRS", 35);
  std::map<int, int> winners;
  for (int pair = 0; pair < pairs; ++pair) {
    const pid_t a = start_render(out, 16), b = start_render(out, 20);
    const int status_a = wait_status(a), status_b = wait_status(b);
    ASSERT_TRUE(WIFEXITED(status_a) && WEXITSTATUS(status_a) == 0) << "pair " << pair;
    ASSERT_TRUE(WIFEXITED(status_b) && WEXITSTATUS(status_b) == 0) << "pair " << pair;
    const SetCheck set = check_set(out);
    ASSERT_EQ(set.problem, "") << "pair " << pair;
    ++winners[set.width];
  }
  std::printf("%d pairs: the 16-wide render's set last in %d, the 20-wide one's in %d\n", pairs, winners[16],
              winners[20]);
  EXPECT_TRUE(leftovers(out).empty()) << leftovers(out).front();
}

// `pxf render ... 2>&1 | head -1`: the reader leaves after the first progress line; the render
// goes on, writes its outputs and exits 0.
TEST(OutputSet, AClosedProgressPipeDoesNotStopTheRender) {
  const std::string out = test_support::temp_dir("output_set", "pipe");
  const std::string command = "bash -c '" + std::string(PXF_EXECUTABLE) + " render --size 16x16 --spp 300 --out " +
                              out + " 2>&1 | head -1 >/dev/null; exit ${PIPESTATUS[0]}'";
  const int status = std::system(command.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "141 is death by SIGPIPE";
  EXPECT_EQ(check_set(out).problem, "");
}

// Where the file system has no symbolic links, each output is renamed over its name: the outputs are
// plain, complete files of the latest run, and the folder holds nothing else of pxf's.
TEST(OutputSet, WithoutSymlinksEachFileIsReplacedWhole) {
  const std::string out = test_support::temp_dir("output_set", "no_symlinks");
  for (const int width : {16, 20}) {
    const std::string command = "LD_PRELOAD=" + std::string(PXF_NO_SYMLINKS_SHIM) + " " + PXF_EXECUTABLE +
                                " render --size " + std::to_string(width) + "x16 --spp 1 --quiet --out " + out +
                                " >/dev/null 2>&1";
    const int status = std::system(command.c_str());
    ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << command;
    for (const char* name : kOutputs) EXPECT_FALSE(fs::is_symlink(out + "/" + name)) << name;
    EXPECT_EQ(check_set(out).width, width) << check_set(out).problem;
    for (const auto& entry : fs::directory_iterator(out))
      if (entry.path().filename() != kSetManifest) {
        EXPECT_NE(entry.path().filename().string().rfind(".pxf-", 0), 0u) << entry.path();
      }
  }
  // A camera path after the render: the render's names go, the frames stay plain files.
  const std::string command = "LD_PRELOAD=" + std::string(PXF_NO_SYMLINKS_SHIM) + " " + PXF_EXECUTABLE +
                              " render --size 16x16 --camera-path turntable:2 --quiet --out " + out + " >/dev/null 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0) << command;
  for (const char* name : kOutputs) EXPECT_FALSE(fs::exists(out + "/" + name)) << name;
  EXPECT_TRUE(fs::is_regular_file(out + "/frame-0001.png"));
}

namespace {

// A child process running `pxf ARGS...` with its stderr in `err_file` and stdout thrown away.
pid_t start_pxf(const std::vector<std::string>& args, const std::string& err_file) {
  std::ofstream(err_file, std::ios::trunc);  // empty before the child starts: no earlier run's lines
  const pid_t pid = fork();
  if (pid == 0) {
    std::freopen(err_file.c_str(), "w", stderr);
    std::freopen("/dev/null", "w", stdout);
    std::vector<char*> argv{const_cast<char*>("pxf")};
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execv(PXF_EXECUTABLE, argv.data());
    _exit(127);
  }
  return pid;
}

// The frames a camera-path render has reported finished on stderr ("\rframe K/N"): K of the last.
int frames_reported(const std::string& err_file) {
  const std::string err = test_support::slurp(err_file);
  const size_t at = err.rfind("frame ");
  return at == std::string::npos ? 0 : std::atoi(err.c_str() + at + 6);
}

// What a camera-path output folder holds: every frame path.json lists, each a whole PNG, and none
// past them; returns the frame count, or -1 with `problem` set.
int check_path_set(const std::string& out, std::string* problem) {
  const auto path = nlohmann::json::parse(test_support::slurp(out + "/path.json"), nullptr, false);
  if (path.is_discarded() || !path.contains("frames")) return *problem = "path.json is missing or not whole", -1;
  const int frames = static_cast<int>(path["frames"].size());
  for (int f = 0; f < frames; ++f) {
    char name[32];
    std::snprintf(name, sizeof name, "/frame-%04d.png", f);
    try {
      if (read_ldr_or_hdr(out + name).width != 16) return *problem = std::string(name) + " has another size", -1;
    } catch (const std::exception& e) {
      return *problem = std::string(name) + " is not whole: " + e.what(), -1;
    }
  }
  char next[32];
  std::snprintf(next, sizeof next, "/frame-%04d.png", frames);
  if (fs::exists(out + next)) return *problem = std::string(next) + " is past path.json's frames", -1;
  return frames;
}

}  // namespace

// Ctrl-C (or SIGTERM) at random moments of a long camera path, after its first frame: the render
// finishes the frame under way, commits every finished frame with path.json, and exits 128 + the
// signal. No frame that the render reported finished is lost. PXF_STRESS_TRIALS sets the count.
TEST(OutputSet, StopSignalsDuringACameraPathLoseNoFinishedFrame) {
  const std::string out = test_support::temp_dir("output_set", "path_signals");
  const std::string err_file = test_support::temp_dir("output_set", "path_signals_err") + ".txt";
  const int trials = env_count("PXF_STRESS_TRIALS", 12);
  std::mt19937 rng(59);
  int frames_kept = 0;
  for (int trial = 0; trial < trials; ++trial) {
    const int signal_number = trial % 3 == 2 ? SIGTERM : SIGINT;
    const pid_t pid = start_pxf({"render", "--size", "16x16", "--camera-path", "turntable:400", "--out", out}, err_file);
    ASSERT_GT(pid, 0);
    int status = 0;
    while (frames_reported(err_file) == 0 && waitpid(pid, &status, WNOHANG) == 0)
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    std::this_thread::sleep_for(std::chrono::milliseconds(std::uniform_int_distribution<int>(0, 400)(rng)));
    const int reported_before = frames_reported(err_file);
    kill(pid, signal_number);
    status = wait_status(pid);
    ASSERT_TRUE(WIFEXITED(status)) << "trial " << trial << ": killed by signal " << WTERMSIG(status);
    ASSERT_EQ(WEXITSTATUS(status), 128 + signal_number) << "trial " << trial;
    std::string problem;
    const int frames = check_path_set(out, &problem);
    ASSERT_GE(frames, 0) << "trial " << trial << ": " << problem;
    ASSERT_GE(frames, reported_before) << "trial " << trial << ": frames lost";
    ASSERT_GE(frames, frames_reported(err_file)) << "trial " << trial << ": frames lost";
    const auto path = nlohmann::json::parse(test_support::slurp(out + "/path.json"));
    EXPECT_TRUE(path["interrupted"].get<bool>());
    EXPECT_EQ(path["frames_planned"].get<int>(), 400);
    frames_kept += frames;
  }
  std::printf("%d stops of a 400-frame path: %d finished frames kept, none lost\n", trials, frames_kept);
  EXPECT_TRUE(leftovers(out).empty()) << leftovers(out).front();
}

// A render, then a camera path, then a shorter path, then a render into one folder: each set shows
// its own names only, no link dangles and one set folder is left.
TEST(OutputSet, SetsOfOtherNamesReplaceEachOtherWithoutDanglingNames) {
  const std::string out = test_support::temp_dir("output_set", "other_names");
  const auto expect_no_dangling = [&](const std::string& step) {
    for (const auto& entry : fs::directory_iterator(out))
      if (entry.is_symlink()) {
        EXPECT_TRUE(fs::exists(entry.path())) << step << ": " << entry.path() << " dangles";
      }
    EXPECT_TRUE(leftovers(out).empty()) << step << ": " << leftovers(out).front();
  };
  ASSERT_EQ(WEXITSTATUS(wait_status(start_render(out, 16))), 0);
  const std::string err_file = out + "-err.txt";
  for (const char* frames : {"turntable:6", "turntable:3"}) {
    ASSERT_EQ(WEXITSTATUS(wait_status(
                  start_pxf({"render", "--size", "16x16", "--camera-path", frames, "--quiet", "--out", out}, err_file))),
              0);
    expect_no_dangling(frames);
    for (const char* name : kOutputs) EXPECT_FALSE(fs::exists(out + "/" + name)) << name;
  }
  std::string problem;
  EXPECT_EQ(check_path_set(out, &problem), 3) << problem;
  ASSERT_EQ(WEXITSTATUS(wait_status(start_render(out, 16))), 0);
  expect_no_dangling("render");
  EXPECT_FALSE(fs::exists(out + "/frame-0000.png"));
  EXPECT_EQ(check_set(out).problem, "");
}

// A .pxf-output of the user's (a folder or a file) is refused with one line before the tracing,
// and nothing of the folder changes.
TEST(OutputSet, AForeignCurrentSetNameIsRefusedByTheCommands) {
  for (const bool folder : {true, false}) {
    for (const char* mode : {"render", "path"}) {
      const std::string out = test_support::temp_dir("output_set", std::string("foreign_") + mode + (folder ? "_dir" : "_file"));
      fs::create_directories(out);
      const std::string current = out + "/" + kCurrentSetLink;
      if (folder) {
        fs::create_directory(current);
        std::ofstream(current + "/final.png") << "the user's";
      } else {
        std::ofstream(current) << "the user's";
      }
      const std::string args = std::string(mode) == "render" ? "render --size 16x16 --spp 100000 --out " + out
                                                              : "render --size 16x16 --camera-path turntable:100000 --out " + out;
      const test_support::PxfResult r = test_support::run_pxf(args, "output_set");
      EXPECT_EQ(r.code, 1) << mode << ": " << r.err;
      EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
      EXPECT_NE(r.err.find("that pxf did not make"), std::string::npos) << r.err;
      size_t entries = 0;
      for ([[maybe_unused]] const auto& entry : fs::directory_iterator(out)) ++entries;
      EXPECT_EQ(entries, 1u) << mode;
      EXPECT_EQ(test_support::slurp(folder ? current + "/final.png" : current), "the user's");
    }
  }
}
