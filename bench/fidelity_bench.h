// pxf bench threshold-fidelity: does the blend keep its promise? Over many seeds, per pixel, the
// empirical perceived variance of the blended HV part of the final image, Var[Y(L - L_lv)] / L_b^2
// (L_b: the mean over seeds of Y(L)), against the threshold t. Pixels are grouped by the blend case
// they take in most seeds (case 2: unfiltered, case 3: mixed, case 5: the bias guard). With
// with_adaptive, the same table for adaptive sampling at equal wall time. Not a test: prints a
// table and writes CSV into the output folder.
#pragma once
#include <string>
#include <vector>
#include "preview/preview.h"

namespace pxf {

struct FidelityBenchSetup {
  Scene scene;
  std::string scene_name;
  PreviewSettings settings;  // filter, sigmas, seed (the seeds run from settings.trace.seed on)
  int width = 0, height = 0;
  std::string out;
  // Also adaptive sampling at equal wall time: per seed and t, an adaptive job (its allocation for
  // that t) read out when it has taken the uniform job's time at each spp (the spp-equivalents).
  bool with_adaptive = false;
};

void run_threshold_fidelity_bench(const FidelityBenchSetup& b, const std::vector<int>& spps,
                                  const std::vector<float>& thresholds, int seeds);

}  // namespace pxf
