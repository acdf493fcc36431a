// OutputSetWriter and the clean-up of pxf's temporaries (issue 38 items 1 and 2): a set is
// replaced as one unit, and nothing that pxf did not name itself is removed.
#include "app/output_set.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <set>

#include "core/error.h"

namespace pxf {
namespace {

namespace fs = std::filesystem;

const std::vector<std::string> kNames = {"a.txt", "b.txt"};
constexpr long kDeadPid = 999999999;  // above pid_max: no process has it

std::string fresh_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("pxf_output_set_" + std::to_string(::getpid())) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir.string();
}

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

void write_text(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

void commit_set(const std::string& dir, const std::string& text) {
  OutputSetWriter writer(dir, kNames);
  for (const std::string& name : kNames) write_text(writer.staging() + "/" + name, text + " " + name);
  writer.commit();
}

std::set<std::string> entries(const std::string& dir) {
  std::set<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.insert(e.path().filename().string());
  return names;
}

TEST(OutputSet, CommitShowsTheWholeSetThroughLinks) {
  const std::string dir = fresh_dir("commit");
  commit_set(dir, "first");
  EXPECT_EQ(read_text(dir + "/a.txt"), "first a.txt");
  EXPECT_EQ(read_text(dir + "/b.txt"), "first b.txt");
  EXPECT_TRUE(fs::is_symlink(dir + "/a.txt"));
  commit_set(dir, "second");
  EXPECT_EQ(read_text(dir + "/a.txt"), "second a.txt");
  EXPECT_EQ(read_text(dir + "/b.txt"), "second b.txt");
  // The first set's folder is gone: the links, .pxf-output and one set folder are left.
  EXPECT_EQ(entries(dir).size(), 4u);
}

TEST(OutputSet, AnUncommittedWriterLeavesTheFolderAsItWas) {
  const std::string dir = fresh_dir("uncommitted");
  commit_set(dir, "kept");
  const std::set<std::string> before = entries(dir);
  {
    OutputSetWriter writer(dir, kNames);
    write_text(writer.staging() + "/a.txt", "half a set");
  }
  EXPECT_EQ(entries(dir), before);
  EXPECT_EQ(read_text(dir + "/a.txt"), "kept a.txt");
}

TEST(OutputSet, PlainFilesOfAnEarlierPxfAreReplacedWhole) {
  const std::string dir = fresh_dir("plain");
  write_text(dir + "/a.txt", "plain a");
  write_text(dir + "/b.txt", "plain b");
  commit_set(dir, "new");
  EXPECT_EQ(read_text(dir + "/a.txt"), "new a.txt");
  EXPECT_EQ(read_text(dir + "/b.txt"), "new b.txt");
  EXPECT_EQ(entries(dir).size(), 4u) << "the adopted plain set was not removed";
}

TEST(OutputSet, ANameThatIsAFolderIsRefusedAndNothingChanges) {
  const std::string dir = fresh_dir("folder_name");
  commit_set(dir, "kept");
  fs::remove(dir + "/b.txt");
  fs::create_directory(dir + "/b.txt");
  OutputSetWriter writer(dir, kNames);
  for (const std::string& name : kNames) write_text(writer.staging() + "/" + name, "new");
  try {
    writer.commit();
    FAIL() << "a folder was replaced";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(dir + "/b.txt"), std::string::npos) << e.what();
  }
  EXPECT_EQ(read_text(dir + "/a.txt"), "kept a.txt");
}

TEST(OutputSet, OnlyPxfsOwnTemporariesOfGoneProcessesAreStale) {
  const std::string dead = std::to_string(kDeadPid), alive = std::to_string(::getpid());
  const std::string current = set_folder_name(kDeadPid, 1);
  // The user's files, whatever they look like.
  for (const char* user : {"thesis.tmp-99999", "report.docx.tmp-4000001", "a.txt.tmp-", "a.txt.tmp-12x", "notes.txt",
                           ".pxf-set-otherhost-999999999-0", ".pxf-setx", ".pxf-link-", "a.txt"})
    EXPECT_FALSE(is_stale_temporary(user, kNames, current)) << user;
  // pxf's own names, of a gone process.
  for (const std::string& own : {"a.txt.tmp-" + dead, set_folder_name(kDeadPid, 0), ".pxf-staging-" + dead})
    EXPECT_TRUE(is_stale_temporary(own, kNames, current)) << own;
  // Of a live process, or the current set: kept.
  EXPECT_FALSE(is_stale_temporary("a.txt.tmp-" + alive, kNames, current));
  EXPECT_FALSE(is_stale_temporary(set_folder_name(::getpid(), 0), kNames, current));
  EXPECT_FALSE(is_stale_temporary(current, kNames, current));
}

TEST(OutputSet, CleanUpRemovesOnlyTheSetsOwnFiles) {
  const std::string dir = fresh_dir("cleanup");
  const std::string stale = dir + "/" + set_folder_name(kDeadPid, 0);
  fs::create_directory(stale);
  write_text(stale + "/a.txt", "stale");
  write_text(dir + "/a.txt.tmp-" + std::to_string(kDeadPid), "stale");
  const std::string foreign = dir + "/" + set_folder_name(kDeadPid, 1);
  fs::create_directory(foreign);
  write_text(foreign + "/a.txt", "stale");
  write_text(foreign + "/mine.tex", "the user's");
  fs::create_directory(dir + "/thesis.tmp-99999");
  write_text(dir + "/thesis.tmp-99999/chapter1.tex", "the user's");
  write_text(dir + "/report.docx.tmp-4000001", "the user's");
  remove_stale_temporaries(dir, kNames);
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_FALSE(fs::exists(dir + "/a.txt.tmp-" + std::to_string(kDeadPid)));
  EXPECT_EQ(read_text(foreign + "/mine.tex"), "the user's");
  EXPECT_FALSE(fs::exists(foreign + "/a.txt"));
  EXPECT_EQ(read_text(dir + "/thesis.tmp-99999/chapter1.tex"), "the user's");
  EXPECT_EQ(read_text(dir + "/report.docx.tmp-4000001"), "the user's");
}

}  // namespace
}  // namespace pxf
