#include "fuzz/fuzz_target.h"

#include <cstdio>
#include <cstdlib>

namespace pxf::fuzz {
void check(bool condition, const char* what) {
  if (condition) return;
  std::fprintf(stderr, "fuzz check failed: %s\n", what);
  std::abort();
}
}  // namespace pxf::fuzz
