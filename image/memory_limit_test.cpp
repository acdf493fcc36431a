// The readers allocate an image's pixels from its header, before any data: a header declaring more
// than the memory this process may take is refused first (a 23 KB EXR can declare
// 40000x40000 pixels, gigabytes once decoded). And available_memory_bytes() sees a limit set with `ulimit -v`.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/memory.h"
#include "image/image.h"

namespace pxf {
namespace {

// AddressSanitizer reserves terabytes of shadow memory and allocates beside the program: an address
// space limit set after it started breaks ASan itself, not the code under test.
#if defined(__SANITIZE_ADDRESS__)
constexpr bool kAddressSanitizer = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kAddressSanitizer = true;
#else
constexpr bool kAddressSanitizer = false;
#endif
#else
constexpr bool kAddressSanitizer = false;
#endif

void put_attribute(std::vector<unsigned char>& out, const std::string& name, const std::string& type,
                   const std::vector<unsigned char>& body) {
  out.insert(out.end(), name.begin(), name.end());
  out.push_back(0);
  out.insert(out.end(), type.begin(), type.end());
  out.push_back(0);
  const int32_t length = static_cast<int32_t>(body.size());
  const auto* l = reinterpret_cast<const unsigned char*>(&length);
  out.insert(out.end(), l, l + 4);
  out.insert(out.end(), body.begin(), body.end());
}

std::vector<unsigned char> ints(std::initializer_list<int32_t> values) {
  std::vector<unsigned char> bytes(4 * values.size());
  std::memcpy(bytes.data(), values.begin(), bytes.size());
  return bytes;
}

// The header of a one-channel float EXR of width x height pixels, and no pixel data.
std::vector<unsigned char> exr_header(int32_t width, int32_t height) {
  std::vector<unsigned char> out = ints({20000630, 2});
  std::vector<unsigned char> channels = {'Y', 0};
  const std::vector<unsigned char> layout = ints({2, 0, 1, 1});  // FLOAT, pLinear + reserved, sampling 1x1
  channels.insert(channels.end(), layout.begin(), layout.end());
  channels.push_back(0);
  put_attribute(out, "channels", "chlist", channels);
  put_attribute(out, "compression", "compression", {0});
  put_attribute(out, "dataWindow", "box2i", ints({0, 0, width - 1, height - 1}));
  put_attribute(out, "displayWindow", "box2i", ints({0, 0, width - 1, height - 1}));
  put_attribute(out, "lineOrder", "lineOrder", {0});
  out.push_back(0);
  return out;
}

// Runs `body` in a child whose address space is limited to what it uses now plus `room` bytes;
// the child's exit status (0 when body returns true).
template <class Body>
int with_address_space_room(uint64_t room, Body body) {
  const pid_t pid = fork();
  if (pid == 0) {
    FILE* status = std::fopen("/proc/self/status", "r");
    char line[256];
    unsigned long vm_kb = 0;
    while (status && std::fgets(line, sizeof(line), status))
      if (std::sscanf(line, "VmSize: %lu kB", &vm_kb) == 1) break;
    if (status) std::fclose(status);
    const rlimit limit{static_cast<rlim_t>(vm_kb) * 1024 + room, RLIM_INFINITY};
    if (vm_kb == 0 || setrlimit(RLIMIT_AS, &limit) != 0) _exit(3);
    _exit(body() ? 0 : 1);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(MemoryLimit, AvailableMemorySeesTheAddressSpaceLimit) {
  if (kAddressSanitizer) GTEST_SKIP() << "an address space limit breaks AddressSanitizer";
  EXPECT_GT(available_memory_bytes(), 0u);
  EXPECT_EQ(with_address_space_room(uint64_t{256} << 20,
                                    [] {
                                      const uint64_t available = available_memory_bytes();
                                      return available > 0 && available <= (uint64_t{256} << 20);
                                    }),
            0);
}

TEST(MemoryLimit, AnImageLargerThanTheMemoryLeftIsRefusedFromItsHeader) {
  if (kAddressSanitizer) GTEST_SKIP() << "an address space limit breaks AddressSanitizer";
  const std::vector<unsigned char> header = exr_header(20000, 20000);  // 1.5 GiB of float pixels
  const int status = with_address_space_room(uint64_t{512} << 20, [&] {
    try {
      read_exr_layers_from_memory(header.data(), header.size(), "big.exr");
    } catch (const Error& e) {
      const std::string message = e.what();
      return message.find("big.exr: 20000x20000 pixels with 1 channels need 1525 MiB, more than the") == 0 &&
             message.find("MiB of memory available") != std::string::npos;
    }
    return false;
  });
  EXPECT_EQ(status, 0) << "1: refused otherwise, or not at all; 3: the limit could not be set; -1: killed";
}

}  // namespace
}  // namespace pxf
