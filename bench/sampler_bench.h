// pxf bench modes of the sampler: Sobol against independent sampling. Not tests: they
// print tables and write CSV into the output folder.
//   sampler-error     unfiltered HDR NRMSE (total, LV and HV alone; RMS over seeds) at several spp
//                     against a high-spp reference from another seed, and paths/s of both samplers measured
//                     back to back (median of rounds)
//   variance-ratio    the estimated Var[L_u] of the pixel mean against its empirical variance
//                     over many seeds, per pixel, for both samplers
#pragma once
#include <string>
#include <vector>
#include "pathtracer/pathtracer.h"

namespace pxf {

struct SamplerBenchSetup {
  Scene scene;
  std::string scene_name;
  TraceParams trace;  // seed, threads, vertices; the sampler is set by the bench
  int width = 0, height = 0;
  std::string out;
};

void run_sampler_error_bench(const SamplerBenchSetup& b, int reference_spp, const std::vector<int>& spps, int rounds,
                             int seeds);
void run_variance_ratio_bench(const SamplerBenchSetup& b, const std::vector<int>& spps, int seeds);

}  // namespace pxf
