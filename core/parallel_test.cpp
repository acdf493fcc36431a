#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <vector>

#include "core/parallel.h"

namespace pxf {
namespace {

TEST(ParallelFor, RunsEveryIndexOnce) {
  for (size_t count : {0u, 1u, 3u, 1000u}) {
    std::vector<std::atomic<int>> runs(count);
    parallel_for(count, [&](size_t i) { ++runs[i]; });
    for (size_t i = 0; i < count; ++i) EXPECT_EQ(runs[i].load(), 1) << "index " << i << " of " << count;
  }
}

TEST(ParallelFor, RethrowsWhatABodyThrew) {
  std::atomic<int> after{0};
  EXPECT_THROW(parallel_for(100, [&](size_t i) {
                 if (i == 7) throw std::runtime_error("item 7");
                 ++after;
               }),
               std::runtime_error);
  EXPECT_LT(after.load(), 100);
}

}  // namespace
}  // namespace pxf
