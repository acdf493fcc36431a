// Every file pxf reads because a user named it (a command-line path, a uri inside a glTF, the
// stats.json beside a named image) is read through here. Only a regular file of bounded size is
// read: a FIFO would block the open forever, a character device like /dev/zero would never end,
// and a directory reads as an error the C++ streams do not name. Each caller passes the bound
// its format allows. The errors are one line naming the file:
//   "PATH: no such file"
//   "PATH: is a directory"
//   "PATH: not a regular file (a FIFO)"          (or a character device, a block device, a socket)
//   "PATH: N bytes, over the limit of M"
//   "PATH: cannot read: <system error>"
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace pxf {

// What a file that is not a regular one is, for messages: "a FIFO", "a character device", "a block
// device", "a socket", "a directory", "a symbolic link", else "of an unknown kind". `mode`: stat's st_mode.
std::string file_kind_name(unsigned mode);

// Throws pxf::Error (above) unless `path` names, after symbolic links, a regular file of at most
// `max_bytes`. Looks with stat() only: nothing is opened.
void check_input_file(const std::string& path, uint64_t max_bytes);

// The whole file. Checked with check_input_file before the open, and again on the open descriptor
// (opened with O_NONBLOCK, so a file swapped for a FIFO in between is refused, not waited on); a
// file that grows past `max_bytes` while it is read is refused too.
std::vector<unsigned char> read_input_file(const std::string& path, uint64_t max_bytes);

// At most its first `count` bytes (enough to tell the format), after the same checks.
std::vector<unsigned char> read_input_file_head(const std::string& path, uint64_t max_bytes, size_t count);

}  // namespace pxf
