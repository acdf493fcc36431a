// OutputSetWriter and the clean-up of pxf's temporaries: a set is
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

void commit_set(const std::string& dir, const std::string& text, const std::vector<std::string>& names = kNames) {
  OutputSetWriter writer(dir, names);
  for (const std::string& name : names) write_text(writer.staging() + "/" + name, text + " " + name);
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

// A set of other names replaces one: the old names the new set lacks go with the old set, and no
// set folder is left behind (a render after a camera path, a 3-frame path after a 6-frame one).
TEST(OutputSet, ASetOfOtherNamesLeavesNoDanglingNameAndNoOrphanFolder) {
  const std::string dir = fresh_dir("other_names");
  commit_set(dir, "six", {"f0", "f1", "f2", "f3", "f4", "f5", "path.json"});
  commit_set(dir, "three", {"f0", "f1", "f2", "path.json"});
  EXPECT_EQ(entries(dir).size(), 6u);  // f0..f2, path.json, .pxf-output and one set folder
  EXPECT_FALSE(fs::is_symlink(dir + "/f3"));
  EXPECT_EQ(read_text(dir + "/f2"), "three f2");
  commit_set(dir, "render");
  EXPECT_EQ(entries(dir), (std::set<std::string>{"a.txt", "b.txt", kCurrentSetLink,
                                                 fs::read_symlink(dir + "/" + kCurrentSetLink).string()}));
  EXPECT_EQ(read_text(dir + "/b.txt"), "render b.txt");
}

// A user's name of the same form that is not one of pxf's links stays.
TEST(OutputSet, ANewSetKeepsTheUsersOwnFilesBesideIt) {
  const std::string dir = fresh_dir("users_beside");
  commit_set(dir, "first", {"a.txt", "c.txt"});
  fs::remove(dir + "/c.txt");
  write_text(dir + "/c.txt", "the user's");
  fs::create_symlink("a.txt", dir + "/mine.txt");
  commit_set(dir, "second");
  EXPECT_EQ(read_text(dir + "/c.txt"), "the user's");
  EXPECT_TRUE(fs::is_symlink(dir + "/mine.txt"));
}

TEST(OutputSet, OnlyTheNamesWrittenAreCommittedAndAMissingOneIsRefused) {
  const std::string dir = fresh_dir("set_names");
  {
    OutputSetWriter writer(dir, {"f0", "f1", "f2"});
    write_text(writer.staging() + "/f0", "frame 0");
    writer.set_names({"f0"});
    writer.commit();
  }
  EXPECT_EQ(read_text(dir + "/f0"), "frame 0");
  EXPECT_FALSE(fs::exists(dir + "/f1"));
  OutputSetWriter writer(dir, {"f0", "f1"});
  write_text(writer.staging() + "/f0", "frame 0 again");
  EXPECT_THROW(writer.commit(), Error);
  EXPECT_EQ(read_text(dir + "/f0"), "frame 0");
}

// DIR/.pxf-output as the user's folder, file or link: refused before any name is touched, and
// left as it was.
TEST(OutputSet, AForeignCurrentSetNameIsRefusedBeforeAnythingIsTouched) {
  for (const std::string kind : {"folder", "file", "link"}) {
    const std::string dir = fresh_dir("foreign_" + kind), current = dir + "/" + kCurrentSetLink;
    if (kind == "folder") {
      fs::create_directory(current);
      write_text(current + "/a.txt", "the user's");
    } else if (kind == "file") {
      write_text(current, "the user's");
    } else {
      fs::create_symlink("/tmp", current);
    }
    const std::set<std::string> before = entries(dir);
    try {
      commit_set(dir, "new");
      FAIL() << kind << " was used";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(current + ": a " + kind + " that pxf did not make"), std::string::npos)
          << e.what();
    }
    EXPECT_EQ(entries(dir), before) << kind;
    if (kind == "folder") {
      EXPECT_EQ(read_text(current + "/a.txt"), "the user's");
    } else if (kind == "file") {
      EXPECT_EQ(read_text(current), "the user's");
    }
    EXPECT_THROW(check_output_folder(dir), Error);
  }
}

// The same writer's check, up front: a folder that takes no new entry is refused.
TEST(OutputSet, AFolderThatTakesNoNewEntryIsRefusedUpFront) {
  EXPECT_THROW(check_output_folder("/proc/self"), Error);
  const std::string dir = fresh_dir("check");
  EXPECT_NO_THROW(check_output_folder(dir + "/new/folder"));
  EXPECT_TRUE(fs::is_directory(dir + "/new/folder"));
  EXPECT_TRUE(entries(dir + "/new/folder").empty());
}

}  // namespace
}  // namespace pxf
