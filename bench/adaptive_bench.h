// pxf bench adaptive: adaptive against uniform sampling, both filtered, on one scene.
// Not a test: prints tables and writes CSV, SVG plots and the images behind the numbers into --out.
//   1. throughput: paths/s of uniform frames and of frames that trace 100 %, 50 % and 10 % of the
//      pixels (scattered at random), back to back, median of --rounds;
//   2. equal wall time: display and HDR NRMSE of the final image of a whole job under a --time budget
//      of N uniform path-tracing frames, adaptive / uniform, median of --rounds alternating rounds;
//      and the pixels of the unfiltered image darker than 0.2x the reference (starved pixels);
//   3. clean over time: the until-clean job of each (check frames 16, then +25 %) until every pixel
//      is case 2 or --clean-cap seconds; the time to clean, or the clean shares at equal time.
#pragma once
#include <string>
#include <vector>

#include "preview/preview.h"

namespace pxf {

struct AdaptiveBenchSetup {
  const Scene& scene;
  std::string scene_name;
  PreviewSettings settings;  // filtered; the adaptive flag is set per run
  int width = 0, height = 0;
  std::string out;
  const Image& reference;  // plain path tracing of another seed, at least 2048 spp
};

struct AdaptiveBenchPlan {
  std::vector<int> budgets;  // equal-time budgets in uniform path-tracing frames
  int rounds = 3;
  double clean_cap_s = 300;  // 0: no clean-over-time part
};

void run_adaptive_bench(const AdaptiveBenchSetup& b, const AdaptiveBenchPlan& plan);

// Pixels whose luminance is below `fraction` of the reference's, among those whose reference
// luminance is at least 1 % of the reference's mean (black pixels have no darker).
size_t pixels_darker_than(const Image& test, const Image& reference, float fraction);

}  // namespace pxf
