#include "image/input_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "core/error.h"

namespace pxf {

std::string file_kind_name(unsigned mode) {
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISLNK(mode)) return "a symbolic link";
  return "of an unknown kind";
}

namespace {

Error too_large(const std::string& path, uint64_t size, uint64_t max_bytes) {
  return Error(path + ": " + std::to_string(size) + " bytes, over the limit of " + std::to_string(max_bytes));
}

[[noreturn]] void fail_system(const std::string& path, int error) {
  if (error == ENOENT || error == ENOTDIR) throw Error(path + ": no such file");
  throw Error(path + ": cannot read: " + std::strerror(error));
}

// The one check, on what stat() or fstat() reported.
void check_status(const std::string& path, const struct stat& status, uint64_t max_bytes) {
  if (S_ISDIR(status.st_mode)) throw Error(path + ": is a directory");
  if (!S_ISREG(status.st_mode)) throw Error(path + ": not a regular file (" + file_kind_name(status.st_mode) + ")");
  const uint64_t size = static_cast<uint64_t>(status.st_size);
  if (size > max_bytes) throw too_large(path, size, max_bytes);
}

class Descriptor {
 public:
  explicit Descriptor(int fd) : fd_(fd) {}
  ~Descriptor() { ::close(fd_); }
  Descriptor(const Descriptor&) = delete;
  Descriptor& operator=(const Descriptor&) = delete;
  int get() const { return fd_; }

 private:
  int fd_;
};

// At most `count` bytes of the checked file. The buffer is sized from fstat; a file that grew since
// is read on in small steps, so that a caller asking for max_bytes + 1 sees it.
std::vector<unsigned char> read_checked(const std::string& path, uint64_t max_bytes, uint64_t count) {
  check_input_file(path, max_bytes);
  // O_NONBLOCK: should the path have become a FIFO since the stat, the open returns at once and the
  // fstat below refuses it.
  const Descriptor fd(::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC));
  if (fd.get() < 0) fail_system(path, errno);
  struct stat status;
  if (::fstat(fd.get(), &status) != 0) fail_system(path, errno);
  check_status(path, status, max_bytes);

  std::vector<unsigned char> bytes(static_cast<size_t>(std::min<uint64_t>(count, static_cast<uint64_t>(status.st_size))));
  size_t done = 0;
  while (done < count) {
    unsigned char more[4096];
    const bool growing = done == bytes.size();
    unsigned char* into = growing ? more : bytes.data() + done;
    const size_t room = growing ? sizeof more : bytes.size() - done;
    const ssize_t n = ::read(fd.get(), into, room);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) fail_system(path, errno);
    if (n == 0) break;
    if (growing) bytes.insert(bytes.end(), more, more + n);
    done += static_cast<size_t>(n);
  }
  bytes.resize(static_cast<size_t>(std::min<uint64_t>(done, count)));
  return bytes;
}

}  // namespace

void check_input_file(const std::string& path, uint64_t max_bytes) {
  struct stat status;
  if (::stat(path.c_str(), &status) != 0) fail_system(path, errno);
  check_status(path, status, max_bytes);
}

std::vector<unsigned char> read_input_file(const std::string& path, uint64_t max_bytes) {
  const uint64_t one_more = max_bytes == UINT64_MAX ? max_bytes : max_bytes + 1;
  std::vector<unsigned char> bytes = read_checked(path, max_bytes, one_more);
  if (bytes.size() > max_bytes) throw too_large(path, bytes.size(), max_bytes);  // it grew while read
  return bytes;
}

std::vector<unsigned char> read_input_file_head(const std::string& path, uint64_t max_bytes, size_t count) {
  return read_checked(path, max_bytes, count);
}

}  // namespace pxf
