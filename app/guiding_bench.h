// pxf bench --guiding (issue 34, docs/guiding.md): path guiding against none, unfiltered, on one
// scene. Not a test: prints tables and writes guiding.csv into --out.
//   1. cost: ms per path-tracing frame at equal spp (the first --frames frames, training included:
//      apply_records after each frame and the iterations' ends), guided / unguided per round, median
//      of --rounds alternating rounds; the field's memory at the end;
//   2. equal wall time: for each budget of --budgets seconds (renderer construction and every frame
//      included), the HDR NRMSE, display NRMSE and outliers of the unfiltered image against the
//      reference, guided / unguided per round, median of --rounds alternating rounds (seeds 101, ...).
#pragma once
#include <string>
#include <vector>

#include "image/image.h"
#include "pathtracer/pathtracer.h"

namespace pxf {

struct GuidingBenchSetup {
  const Scene& scene;
  TraceParams params;  // the guiding flag is set per run
  int width = 0, height = 0;
  std::string out;
  const Image& reference;  // plain path tracing of another seed, at least 2048 spp
};

struct GuidingBenchPlan {
  std::vector<int> budgets_s = {2, 8};
  int rounds = 5;
  int cost_frames = 32;
};

void run_guiding_bench(const GuidingBenchSetup& b, const GuidingBenchPlan& plan);

}  // namespace pxf
