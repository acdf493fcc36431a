// pxf bench guiding-ab (docs/guiding.md): path guiding against none, unfiltered, on one
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

#include "bench/guiding_bound.h"
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

// pxf bench guiding-bound (docs/guiding.md, "How far first-vertex guiding can go"): at first
// vertices drawn over the image, the variance of the indirect light's estimate under cosine
// sampling, the trained field, the light known exactly and the least any guide can give
// (bench/guiding_bound.h); per point and summed over the points (as the HDR error sums
// pixels). Then the image: guiding changes only the HV part of a pixel (its direct light, LV, is
// NEE's), so with HV's share of the error variance of two unguided renders of two seeds, the HDR
// error ratio at equal samples is at least sqrt(LV share + HV share x the floor) for any guide of
// the first vertices, at no cost. Prints a table and writes guiding_bound.csv into --out.
struct GuidingBoundBenchSetup {
  const Scene& scene;
  TraceParams params;
  int width = 0, height = 0;
  std::string out;
  int lv_hv_spp = 32;  // samples of the two renders that split the image's error into LV and HV
};
void run_guiding_bound_bench(const GuidingBoundBenchSetup& b, const GuidingBoundSettings& settings);

}  // namespace pxf
