#include "app/guiding_bench.h"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/timing.h"
#include "image/metrics.h"

namespace pxf {

namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

TraceParams with_guiding(TraceParams p, bool guiding, uint64_t seed) {
  p.guiding = guiding;
  p.seed = seed;
  return p;
}

struct TimedResult {
  int spp = 0;
  double hdr = 0, display = 0;
  size_t outliers = 0;
  size_t field_bytes = 0;
};

// A whole job under a wall-clock budget: the renderer is built inside it, and frames are added
// while the budget lasts (the last one may end past it, as in pxf render --time).
TimedResult timed_job(const GuidingBenchSetup& b, bool guiding, uint64_t seed, double budget_ms) {
  const auto start = Clock::now();
  ProgressiveRenderer renderer(b.scene, with_guiding(b.params, guiding, seed), b.width, b.height);
  do renderer.add_frame();
  while (ms_since(start) < budget_ms);
  TimedResult r;
  r.spp = renderer.frames();
  const Image image = renderer.unfiltered_image();
  const DisplayMetrics m = compare_display(image, b.reference);
  r.hdr = m.hdr.nrmse_percent;
  r.display = m.display_nrmse_percent;
  r.outliers = count_outliers(image, b.reference).outliers;
  r.field_bytes = renderer.guiding_memory_bytes();
  return r;
}

}  // namespace

void run_guiding_bench(const GuidingBenchSetup& b, const GuidingBenchPlan& plan) {
  std::filesystem::create_directories(b.out);
  std::ostringstream csv;
  csv << "part,budget_s,round,guiding,spp,ms_per_frame,hdr_nrmse,display_nrmse,outliers,field_bytes\n";

  // 1. Cost at equal spp.
  std::vector<double> off_ms, on_ms, ratios;
  size_t field_bytes = 0;
  for (int round = 0; round < plan.rounds; ++round) {
    double ms[2];
    for (int g = 0; g < 2; ++g) {
      ProgressiveRenderer renderer(b.scene, with_guiding(b.params, g == 1, 1000 + round), b.width, b.height);
      const auto start = Clock::now();
      for (int i = 0; i < plan.cost_frames; ++i) renderer.add_frame();
      ms[g] = ms_since(start) / plan.cost_frames;
      if (g == 1) field_bytes = renderer.guiding_memory_bytes();
      csv << "cost,," << round << "," << g << "," << plan.cost_frames << "," << ms[g] << ",,,,"
          << renderer.guiding_memory_bytes() << "\n";
    }
    off_ms.push_back(ms[0]);
    on_ms.push_back(ms[1]);
    ratios.push_back(ms[1] / ms[0]);
  }
  std::printf("guiding bench: %dx%d, %d rounds\n", b.width, b.height, plan.rounds);
  std::printf("cost, %d frames: unguided %.1f ms/frame, guided %.1f ms/frame (medians); guided / unguided per round:",
              plan.cost_frames, median_of(off_ms), median_of(on_ms));
  for (double r : ratios) std::printf(" %.2f", r);
  std::printf(", median %.2f; field %zu bytes\n", median_of(ratios), field_bytes);

  // 2. Equal wall time.
  std::printf("%8s %14s %14s %10s %14s %14s %10s %12s %12s\n", "budget_s", "spp off/on", "HDR off %",
              "HDR on %", "display off %", "display on %", "outl. off", "outl. on", "HDR / disp.");
  for (int budget : plan.budgets_s) {
    std::vector<double> spp[2], hdr[2], display[2], outliers[2], hdr_ratio, display_ratio;
    for (int round = 0; round < plan.rounds; ++round) {
      TimedResult r[2];
      for (int g = 0; g < 2; ++g) {
        r[g] = timed_job(b, g == 1, 101 + round, budget * 1000.0);
        spp[g].push_back(r[g].spp);
        hdr[g].push_back(r[g].hdr);
        display[g].push_back(r[g].display);
        outliers[g].push_back(static_cast<double>(r[g].outliers));
        csv << "time," << budget << "," << round << "," << g << "," << r[g].spp << ",," << r[g].hdr << ","
            << r[g].display << "," << r[g].outliers << "," << r[g].field_bytes << "\n";
      }
      hdr_ratio.push_back(r[1].hdr / r[0].hdr);
      display_ratio.push_back(r[1].display / r[0].display);
    }
    std::printf("%8d %7.0f/%-6.0f %14.2f %10.2f %14.2f %14.2f %10.0f %12.0f %6.2f/%-5.2f\n", budget,
                median_of(spp[0]), median_of(spp[1]), median_of(hdr[0]), median_of(hdr[1]), median_of(display[0]),
                median_of(display[1]), median_of(outliers[0]), median_of(outliers[1]), median_of(hdr_ratio),
                median_of(display_ratio));
  }
  const std::string path = b.out + "/guiding.csv";
  std::ofstream file(path);
  file << csv.str();
  if (!file) throw Error(path + ": cannot write");
  std::printf("wrote %s\n", path.c_str());
}

}  // namespace pxf
