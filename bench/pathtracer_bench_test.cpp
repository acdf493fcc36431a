// Throughput figures, not a pass/fail test (tests never assert wall time). Run with
//   bench_tests --gtest_also_run_disabled_tests --gtest_filter=IntegratorBench.*
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>

#include "bench/pathtracer_bench.h"
#include "scene/load.h"

namespace pxf {
namespace {

TEST(IntegratorBench, DISABLED_CornellBox512) {
  const char* name = std::getenv("PXF_BENCH_SCENE");
  Scene scene = load_scene(name ? name : "cornell");
  TraceParams params;  // 6 vertices, RR from vertex 3, all cores unless PXF_BENCH_THREADS
  if (const char* threads = std::getenv("PXF_BENCH_THREADS")) params.threads = std::atoi(threads);
  BenchResult r = run_benchmark(scene, 512, 512, params, 3, 20);
  std::printf("%s: %s\n", name ? name : "cornell", format_benchmark(r).c_str());
  EXPECT_GT(r.paths_per_s, 0.0);
}

}  // namespace
}  // namespace pxf
