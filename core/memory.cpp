#include "core/memory.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <sstream>
#include <string>

namespace pxf {

namespace {

constexpr uint64_t kUnknown = UINT64_MAX;

// "KEY: VALUE kB" from a /proc file, in bytes; kUnknown without it.
uint64_t proc_kilobytes(const char* file, const std::string& key) {
  std::ifstream in(file);
  std::string line;
  while (std::getline(in, line)) {
    if (line.compare(0, key.size(), key) != 0) continue;
    std::istringstream fields(line.substr(key.size()));
    uint64_t value = 0;
    return fields >> value ? value * 1024 : kUnknown;
  }
  return kUnknown;
}

uint64_t system_available() {
  const uint64_t meminfo = proc_kilobytes("/proc/meminfo", "MemAvailable:");
  if (meminfo != kUnknown) return meminfo;
  const long pages = sysconf(_SC_AVPHYS_PAGES), page_size = sysconf(_SC_PAGESIZE);
  return pages > 0 && page_size > 0 ? static_cast<uint64_t>(pages) * static_cast<uint64_t>(page_size) : kUnknown;
}

// The cgroup v2 path of this process ("0::/PATH" in /proc/self/cgroup), or "".
std::string cgroup_path() {
  std::ifstream in("/proc/self/cgroup");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("0::", 0) == 0) return line.substr(3);
  return "";
}

uint64_t read_number(const std::string& file) {
  std::ifstream in(file);
  std::string text;
  if (!(in >> text) || text == "max") return kUnknown;
  std::istringstream number(text);
  uint64_t value = 0;
  return number >> value ? value : kUnknown;
}

uint64_t cgroup_room() {
  const std::string path = cgroup_path();
  if (path.empty()) return kUnknown;
  const std::string folder = "/sys/fs/cgroup" + (path == "/" ? std::string() : path);
  const uint64_t limit = read_number(folder + "/memory.max"), used = read_number(folder + "/memory.current");
  if (limit == kUnknown || used == kUnknown) return kUnknown;
  return limit > used ? limit - used : 0;
}

uint64_t address_space_room() {
  struct rlimit limit {};
  if (getrlimit(RLIMIT_AS, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY) return kUnknown;
  const uint64_t used = proc_kilobytes("/proc/self/status", "VmSize:");
  if (used == kUnknown) return kUnknown;
  return limit.rlim_cur > used ? limit.rlim_cur - used : 0;
}

}  // namespace

uint64_t available_memory_bytes() {
  const uint64_t room = std::min({system_available(), cgroup_room(), address_space_room()});
  return room == kUnknown ? 0 : room;
}

}  // namespace pxf
