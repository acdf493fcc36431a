#include "bench/guiding_bench.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "bench/bench_harness.h"
#include "core/timing.h"
#include "image/metrics.h"

namespace pxf {

namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

TraceParams with_guiding(TraceParams p, bool guiding, uint64_t seed) {
  p.guiding = guiding ? GuidingMode::On : GuidingMode::Off;
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

namespace {

// The shares of the image's error variance in LV (the direct light at the first vertex, which
// guiding does not change) and HV, from two unguided renders of `spp` samples and two seeds: per
// pixel the squared difference of the luminances over 2 is the variance of one render's mean.
struct ErrorShares {
  double lv = 0.0, hv = 0.0;  // of the variance of LV + HV
};
// The two renders' seeds: this past the bench's seed, and the next.
constexpr uint64_t kErrorShareSeedOffset = 1000;

ErrorShares lv_hv_error_shares(const GuidingBoundBenchSetup& b, int spp) {
  Accumulation acc[2];
  for (int i = 0; i < 2; ++i) {
    TraceParams params = b.params;
    params.guiding = GuidingMode::Off;
    params.seed = b.params.seed + kErrorShareSeedOffset + static_cast<uint64_t>(i);
    ProgressiveRenderer renderer(b.scene, params, b.width, b.height);
    for (int f = 0; f < spp; ++f) renderer.add_frame();
    acc[i] = renderer.accumulation();
  }
  const auto lum = [](const glm::vec3& c) { return double(luminance(c.r, c.g, c.b)); };
  double lv = 0.0, hv = 0.0, total = 0.0;
  for (size_t p = 0; p < acc[0].lv_mean.size(); ++p) {
    const double dl = lum(acc[0].lv_mean[p]) - lum(acc[1].lv_mean[p]), dh = lum(acc[0].hv_mean[p]) - lum(acc[1].hv_mean[p]);
    lv += dl * dl;
    hv += dh * dh;
    total += (dl + dh) * (dl + dh);
  }
  return total > 0.0 ? ErrorShares{lv / total, hv / total} : ErrorShares{};
}

}  // namespace

void run_guiding_bound_bench(const GuidingBoundBenchSetup& b, const GuidingBoundSettings& settings) {
  std::printf("guiding bound: %dx%d, %d points, %d x %d cells per cube face, %d paths per cell, field trained %d frames\n",
              b.width, b.height, settings.points, settings.face_cells, settings.face_cells, settings.paths_per_cell,
              settings.train_frames);
  const GuidingBound bound = measure_guiding_bound(b.scene, b.params, b.width, b.height, settings);
  const std::vector<GuidingBoundPoint>& points = bound.points;
  std::ostringstream csv;
  csv << "x,y,indirect,cosine_variance,field_variance,known_light_variance,least_variance,floor_variance,deeper_variance,"
         "field_alpha\n";
  std::printf("%5s %5s %10s %12s %9s %9s %9s %9s %9s %7s\n", "x", "y", "indirect", "cos rel.var", "field", "known",
              "least", "floor", "deeper", "alpha");
  GuidingBoundPoint sum;
  for (const GuidingBoundPoint& p : points) {
    csv << p.x << "," << p.y << "," << p.indirect << "," << p.cosine << "," << p.field << "," << p.known_light << ","
        << p.least << "," << p.floor << "," << p.deeper << "," << p.field_alpha << "\n";
    const double c = p.cosine > 0.0 ? p.cosine : 1.0;
    std::printf("%5d %5d %10.4f %12.3f %9.3f %9.3f %9.3f %9.3f %9.3f %7.2f\n", p.x, p.y, p.indirect,
                p.indirect > 0.0 ? p.cosine / (p.indirect * p.indirect) : 0.0, p.field / c, p.known_light / c,
                p.least / c, p.floor / c, p.deeper / c, p.field_alpha);
    sum.cosine += p.cosine;
    sum.field += p.field;
    sum.known_light += p.known_light;
    sum.least += p.least;
    sum.floor += p.floor;
    sum.deeper += p.deeper;
  }
  if (points.empty() || !(sum.cosine > 0.0)) {
    std::printf("no first vertex with a diffuse lobe and indirect light\n");
  } else {
    std::printf("variance summed over the points, against cosine sampling: field %.3f, light known exactly (alpha 0.5) %.3f, "
                "least over the cells %.3f, floor of any guide %.3f; deeper vertices' share under cosine sampling %.3f\n",
                sum.field / sum.cosine, sum.known_light / sum.cosine, sum.least / sum.cosine, sum.floor / sum.cosine,
                sum.deeper / sum.cosine);
    // What that means for the image: guiding changes the HV part only (b.lv_hv_spp-sample renders).
    const ErrorShares shares = lv_hv_error_shares(b, b.lv_hv_spp);
    const double floor = sum.floor / sum.cosine, field = sum.field / sum.cosine;
    std::printf("error variance of %d-spp unguided renders (seeds %llu, %llu): LV %.3f, HV %.3f of LV + HV\n", b.lv_hv_spp,
                static_cast<unsigned long long>(b.params.seed + kErrorShareSeedOffset),
                static_cast<unsigned long long>(b.params.seed + kErrorShareSeedOffset + 1),
                shares.lv, shares.hv);
    std::printf("HDR error at equal samples against unguided, every first vertex guided, at no cost: at least %.3f with any "
                "guide (sqrt(LV + HV x floor)); %.3f with the field\n",
                std::sqrt(shares.lv + shares.hv * floor), std::sqrt(shares.lv + shares.hv * field));
  }
  if (bound.chains_left_out)
    std::printf("note: the renderer's first vertices here also trace specular chains, which the cells leave out: these "
                "figures do not bound the renderer (--specular-chains off, or a scene without perfectly specular meshes)\n");
  write_bench_text(b.out + "/guiding_bound.csv", csv.str());
  std::printf("wrote %s/guiding_bound.csv\n", b.out.c_str());
}

}  // namespace pxf
