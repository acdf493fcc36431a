// check_input_file / read_input_file: only a regular file of bounded size is read, and every
// refusal is one line naming the file (image/input_file.h).
#include <gtest/gtest.h>

#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>

#include "core/error.h"
#include "image/input_file.h"

namespace fs = std::filesystem;
using namespace pxf;

namespace {

std::string temp_folder(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("pxf_input_file_test_" + std::to_string(::getpid())) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir.string();
}

std::string write_text(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

// The pxf::Error message of `call`, or "" when it does not throw.
std::string error_of(const std::function<void()>& call) {
  try {
    call();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(InputFile, ReadsARegularFileWithinTheBound) {
  const std::string path = write_text(temp_folder("regular") + "/a.txt", "hello");
  EXPECT_NO_THROW(check_input_file(path, 5));
  const std::vector<unsigned char> bytes = read_input_file(path, 5);
  EXPECT_EQ(std::string(bytes.begin(), bytes.end()), "hello");
  const std::vector<unsigned char> head = read_input_file_head(path, 5, 2);
  EXPECT_EQ(std::string(head.begin(), head.end()), "he");
  EXPECT_TRUE(read_input_file(write_text(temp_folder("empty") + "/e.txt", ""), 5).empty());
}

TEST(InputFile, ReadsThroughASymbolicLink) {
  const std::string dir = temp_folder("link");
  write_text(dir + "/target.txt", "abc");
  fs::create_symlink(dir + "/target.txt", dir + "/link.txt");
  EXPECT_EQ(read_input_file(dir + "/link.txt", 3).size(), 3u);
}

TEST(InputFile, RefusesAFileOverTheBound) {
  const std::string path = write_text(temp_folder("large") + "/a.txt", "hello");
  const std::string message = path + ": 5 bytes, over the limit of 4";
  EXPECT_EQ(error_of([&] { check_input_file(path, 4); }), message);
  EXPECT_EQ(error_of([&] { read_input_file(path, 4); }), message);
  EXPECT_EQ(error_of([&] { read_input_file_head(path, 4, 1); }), message);
}

TEST(InputFile, RefusesAMissingFile) {
  const std::string path = temp_folder("missing") + "/none.exr";
  EXPECT_EQ(error_of([&] { read_input_file(path, 100); }), path + ": no such file");
}

TEST(InputFile, RefusesADirectory) {
  const std::string dir = temp_folder("directory");
  EXPECT_EQ(error_of([&] { check_input_file(dir, 100); }), dir + ": is a directory");
  EXPECT_EQ(error_of([&] { read_input_file(dir, 100); }), dir + ": is a directory");
}

// Opening a FIFO for reading blocks until a writer comes: the refusal must come without an open.
TEST(InputFile, RefusesAFifoWithoutBlocking) {
  const std::string path = temp_folder("fifo") + "/pipe.exr";
  ASSERT_EQ(::mkfifo(path.c_str(), 0600), 0);
  EXPECT_EQ(error_of([&] { read_input_file(path, 100); }), path + ": not a regular file (a FIFO)");
  EXPECT_EQ(error_of([&] { read_input_file_head(path, 100, 10); }), path + ": not a regular file (a FIFO)");
}

TEST(InputFile, RefusesACharacterDevice) {
  EXPECT_EQ(error_of([] { read_input_file("/dev/zero", 100); }), "/dev/zero: not a regular file (a character device)");
  EXPECT_EQ(error_of([] { read_input_file("/dev/null", 100); }), "/dev/null: not a regular file (a character device)");
}

TEST(InputFile, RefusesASocket) {
  const std::string path = temp_folder("socket") + "/s";
  const int fd = ::socket(AF_UNIX, SOCK_STREAM, 0);
  ASSERT_GE(fd, 0);
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  ASSERT_LT(path.size(), sizeof address.sun_path);
  path.copy(address.sun_path, path.size());
  ASSERT_EQ(::bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address), 0);
  EXPECT_EQ(error_of([&] { read_input_file(path, 100); }), path + ": not a regular file (a socket)");
  ::close(fd);
}

TEST(InputFile, RefusesAnUnreadableFile) {
  if (::geteuid() == 0) GTEST_SKIP() << "root reads every file";
  const std::string path = write_text(temp_folder("unreadable") + "/a.txt", "x");
  fs::permissions(path, fs::perms::none);
  EXPECT_EQ(error_of([&] { read_input_file(path, 100); }), path + ": cannot read: Permission denied");
}
