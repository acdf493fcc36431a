#include "bench/adaptive_bench.h"
#include "bench/bench_harness.h"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <memory>
#include <random>
#include <sstream>

#include "bench/bench_runs.h"
#include "bench/plot.h"
#include "core/timing.h"
#include "gl/cpu_reference.h"
#include "image/image.h"

namespace pxf {

namespace {

PreviewSettings with_adaptive(PreviewSettings s, bool adaptive, AdaptiveGoal goal = AdaptiveGoal::Error) {
  s.adaptive = adaptive;
  s.adaptive_params.goal = goal;
  return s;
}

float luminance_at(const Image& rgb, size_t p) {
  return 0.2126f * rgb.pixels[3 * p] + 0.7152f * rgb.pixels[3 * p + 1] + 0.0722f * rgb.pixels[3 * p + 2];
}

// ---------------------------------------------------------------------------------- 1. throughput

// A mask tracing `share` of the pixels, scattered at random (fixed seed): the least coherent case;
// the allocation's dilated regions are clustered.
std::vector<uint8_t> scattered_mask(size_t pixels, double share) {
  std::mt19937 rng(1234);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<uint8_t> mask(pixels);
  for (uint8_t& m : mask) m = u(rng) < share;
  return mask;
}

void throughput_table(const AdaptiveBenchSetup& b, int rounds) {
  ProgressiveRenderer renderer(b.scene, b.settings.trace, b.width, b.height);
  for (int i = 0; i < 3; ++i) renderer.add_frame();  // warm-up: threads, caches
  const size_t pixels = static_cast<size_t>(b.width) * b.height;
  struct Mode {
    const char* name;
    std::vector<uint8_t> mask;  // empty: add_frame() as before adaptive sampling
    std::vector<double> paths_per_s;
  };
  std::vector<Mode> modes = {{"uniform frame", {}, {}},
                             {"mask, 100 % active", std::vector<uint8_t>(pixels, 1), {}},
                             {"mask, 50 % active", scattered_mask(pixels, 0.5), {}},
                             {"mask, 10 % active", scattered_mask(pixels, 0.1), {}}};
  constexpr int kFramesPerRun = 4;
  for (int round = 0; round < rounds; ++round)
    for (Mode& mode : modes) {
      const uint64_t before = renderer.stats().paths;
      const auto start = BenchClock::now();
      // A 10 % mask traces a tenth of the paths a frame: ten times the frames for a like duration.
      const double share = mode.mask.empty() ? 1.0 : std::max(0.01, static_cast<double>(std::count(
                                                                         mode.mask.begin(), mode.mask.end(), 1)) /
                                                                         static_cast<double>(pixels));
      const int frames = static_cast<int>(kFramesPerRun / share + 0.5);
      for (int f = 0; f < frames; ++f) mode.mask.empty() ? renderer.add_frame() : renderer.add_frame(mode.mask);
      mode.paths_per_s.push_back(static_cast<double>(renderer.stats().paths - before) / (elapsed_ms(start) / 1000.0));
    }
  const double uniform = median_of(modes[0].paths_per_s);
  std::printf("\n1. path tracer throughput, %dx%d (median of %d rounds, the modes back to back in each):\n", b.width,
              b.height, rounds);
  std::ostringstream csv;
  csv << "mode,median_paths_per_s,ratio_to_uniform\n";
  for (const Mode& mode : modes) {
    const double m = median_of(mode.paths_per_s);
    std::printf("   %-20s %12.0f paths/s  %6.3fx\n", mode.name, m, m / uniform);
    csv << mode.name << "," << m << "," << m / uniform << "\n";
  }
  write_bench_text(b.out + "/adaptive_throughput_" + b.scene_name + ".csv", csv.str());
}

// ---------------------------------------------------------------------------------- 2. equal time

// The median path-tracing frame of a short uniform, unfiltered run: the budgets' unit.
double uniform_frame_ms(const AdaptiveBenchSetup& b) {
  PreviewSettings plain = b.settings;
  plain.filter.kind = FilterKind::None;
  plain.adaptive = false;
  Preview warm(b.scene, plain, b.width, b.height);
  std::vector<double> frame_ms;
  for (int i = 0; i < 8; ++i) {
    warm.add_frame(i == 7, i == 7);
    frame_ms.push_back(warm.last_times().path_tracing);
  }
  return median_of(frame_ms);
}

struct EqualTimeFigures {
  std::vector<double> uniform_spp, adaptive_frames, adaptive_paths;
  std::vector<double> uniform_display, adaptive_display, display_ratio, hdr_ratio;
  std::vector<double> uniform_dark, adaptive_dark;
};

void equal_time_table(const AdaptiveBenchSetup& b, const AdaptiveBenchPlan& plan) {
  const double pt_ms = uniform_frame_ms(b);
  TonemapParams tonemap;
  tonemap.log_average = static_cast<float>(cpu_log_average(b.reference, tonemap.delta));
  write_png(b.out + "/adaptive_" + b.scene_name + "_reference.png", cpu_tonemap(b.reference, tonemap));
  std::ostringstream csv;
  csv << "budget_frames,budget_ms,round,mode,frames,paths_per_pixel,used_ms,hdr_nrmse_percent,display_nrmse_percent,"
         "flip,unfiltered_dark_pixels\n";
  std::printf("\n2. filtered, equal wall time of the whole job (--time = N uniform path-tracing frames of %.1f ms;\n"
              "   median of %d rounds, the order alternating; ratios are medians of the per-round ratios):\n",
              pt_ms, plan.rounds);
  std::printf("   budget | uniform spp  display | adaptive frames paths/px  display | display ratio  HDR ratio |"
              " dark px unif / adapt\n");
  PlotSeries uniform_points{"uniform", {}, {}, true}, adaptive_points{"adaptive", {}, {}, true};
  for (int budget : plan.budgets) {
    EqualTimeFigures f;
    for (int round = 0; round < plan.rounds; ++round) {
      TimedRun runs[2];
      for (int k = 0; k < 2; ++k) {
        const bool adaptive = (k + round) % 2 == 1;  // uniform first in even rounds
        runs[adaptive] = run_timed(b.scene, with_adaptive(b.settings, adaptive), b.width, b.height, budget * pt_ms,
                                   b.reference);
      }
      const TimedRun &u = runs[0], &a = runs[1];
      const size_t dark_u = pixels_darker_than(u.unfiltered, b.reference, 0.2f);
      const size_t dark_a = pixels_darker_than(a.unfiltered, b.reference, 0.2f);
      for (int k = 0; k < 2; ++k) {
        const TimedRun& r = runs[k];
        csv << budget << "," << budget * pt_ms << "," << round << "," << (k ? "adaptive" : "uniform") << "," << r.spp
            << "," << r.paths_per_pixel << "," << r.used_ms << "," << r.error.hdr_nrmse << ","
            << r.error.display_nrmse << "," << r.error.flip << "," << (k ? dark_a : dark_u) << "\n";
      }
      f.uniform_spp.push_back(u.spp), f.adaptive_frames.push_back(a.spp), f.adaptive_paths.push_back(a.paths_per_pixel);
      f.uniform_display.push_back(u.error.display_nrmse), f.adaptive_display.push_back(a.error.display_nrmse);
      f.display_ratio.push_back(a.error.display_nrmse / u.error.display_nrmse);
      f.hdr_ratio.push_back(a.error.hdr_nrmse / u.error.hdr_nrmse);
      f.uniform_dark.push_back(static_cast<double>(dark_u)), f.adaptive_dark.push_back(static_cast<double>(dark_a));
      uniform_points.x.push_back(u.used_ms / 1000), uniform_points.y.push_back(u.error.display_nrmse);
      adaptive_points.x.push_back(a.used_ms / 1000), adaptive_points.y.push_back(a.error.display_nrmse);
      if (round + 1 == plan.rounds) {
        const std::string prefix = b.out + "/adaptive_" + b.scene_name + "_" + std::to_string(budget) + "_";
        write_png(prefix + "uniform.png", cpu_tonemap(u.image, tonemap));
        write_png(prefix + "adaptive.png", cpu_tonemap(a.image, tonemap));
      }
    }
    std::printf("   %6d | %11.0f  %6.2f %% | %15.0f %8.1f  %6.2f %% | %12.3fx  %8.3fx | %7.0f / %.0f\n", budget,
                median_of(f.uniform_spp), median_of(f.uniform_display), median_of(f.adaptive_frames),
                median_of(f.adaptive_paths), median_of(f.adaptive_display), median_of(f.display_ratio),
                median_of(f.hdr_ratio), median_of(f.uniform_dark), median_of(f.adaptive_dark));
    std::fflush(stdout);
  }
  write_bench_text(b.out + "/adaptive_equal_time_" + b.scene_name + ".csv", csv.str());
  write_svg_plot(b.out + "/adaptive_error_vs_time_" + b.scene_name + ".svg",
                 {"display NRMSE at equal wall time: " + b.scene_name, "wall time (s)", "display NRMSE (%)", true, true},
                 {uniform_points, adaptive_points});
}

// ------------------------------------------------------------------------------ 3. clean over time

struct CleanPoint {
  double ms = 0;
  int frames = 0;
  double paths_per_pixel = 0, share = 0;
};

// The until-clean job of `pxf render --until-clean` (the same check frames) of both modes, up to
// cap_ms each, run interleaved: each step advances the mode that has used less time by one frame,
// and each mode's clock runs only during its own steps. A machine shared with other work then slows
// both alike, which two runs one after the other would not ensure.
struct CleanJob {
  std::unique_ptr<Preview> preview;
  GrowingSchedule checks = clean_checks();
  double ms = 0;
  bool done = false;
  std::vector<CleanPoint> points;
};

void step(CleanJob& job, double cap_ms) {
  const auto start = BenchClock::now();
  Preview& preview = *job.preview;
  const bool check = job.checks.due(preview.samples() + 1);
  preview.add_frame(/*last_frame=*/check, /*display=*/check);
  job.ms += elapsed_ms(start);
  if (check) {
    job.checks.done(preview.samples());
    job.points.push_back({job.ms, preview.samples(), sample_counts(preview.pixel_samples()).mean,
                          preview.case2_share()});
  }
  job.done = (check && preview.case2_share() == 1.0) || job.ms >= cap_ms;
}

void clean_over_time(const AdaptiveBenchSetup& b, double cap_ms, CleanJob (&jobs)[2]) {
  for (int adaptive = 0; adaptive < 2; ++adaptive) {
    const auto start = BenchClock::now();
    jobs[adaptive].preview =
        std::make_unique<Preview>(b.scene, with_adaptive(b.settings, adaptive != 0, AdaptiveGoal::Clean), b.width, b.height);
    jobs[adaptive].ms = elapsed_ms(start);
  }
  while (!jobs[0].done || !jobs[1].done) {
    const int next = jobs[0].done ? 1 : jobs[1].done ? 0 : (jobs[1].ms < jobs[0].ms ? 1 : 0);
    step(jobs[next], cap_ms);
  }
}

// The clean share of the last check at or before `ms` (0 before the first check).
double share_at(const std::vector<CleanPoint>& points, double ms) {
  double share = 0;
  for (const CleanPoint& p : points)
    if (p.ms <= ms) share = p.share;
  return share;
}

void clean_table(const AdaptiveBenchSetup& b, double cap_s) {
  std::printf("\n3. until clean (every pixel case 2, t = %g), at most %.0f s each, the two jobs interleaved frame by frame:\n",
              b.settings.threshold, cap_s);
  CleanJob jobs[2];
  clean_over_time(b, cap_s * 1000, jobs);
  const std::vector<CleanPoint> runs[2] = {jobs[0].points, jobs[1].points};
  std::ostringstream csv;
  csv << "mode,ms,frames,paths_per_pixel,case2_share\n";
  std::vector<PlotSeries> series;
  for (int adaptive = 0; adaptive < 2; ++adaptive) {
    const char* name = adaptive ? "adaptive" : "uniform";
    PlotSeries s{name, {}, {}, false};
    for (const CleanPoint& p : runs[adaptive]) {
      csv << name << "," << p.ms << "," << p.frames << "," << p.paths_per_pixel << "," << p.share << "\n";
      s.x.push_back(p.ms / 1000), s.y.push_back(100 * p.share);
    }
    series.push_back(s);
    const CleanPoint last = runs[adaptive].empty() ? CleanPoint{} : runs[adaptive].back();
    std::printf("   %-8s %s after %.1f s: %d frames, %.1f paths/pixel, %.2f %% clean\n", name,
                last.share == 1.0 ? "clean" : "not clean", last.ms / 1000, last.frames, last.paths_per_pixel,
                100 * last.share);
  }
  const CleanPoint u = runs[0].empty() ? CleanPoint{} : runs[0].back();
  const CleanPoint a = runs[1].empty() ? CleanPoint{} : runs[1].back();
  if (u.share == 1.0 && a.share == 1.0) {
    std::printf("   time to clean, adaptive / uniform: %.3fx\n", a.ms / u.ms);
  } else {
    const double t = std::min(u.ms, a.ms);
    std::printf("   at equal time %.1f s: uniform %.2f %% clean, adaptive %.2f %% clean\n", t / 1000,
                100 * share_at(runs[0], t), 100 * share_at(runs[1], t));
  }
  write_bench_text(b.out + "/adaptive_clean_" + b.scene_name + ".csv", csv.str());
  write_svg_plot(b.out + "/adaptive_clean_vs_time_" + b.scene_name + ".svg",
                 {"clean (case 2) pixels: " + b.scene_name, "wall time (s)", "clean pixels (%)", true, false}, series);
}

}  // namespace

size_t pixels_darker_than(const Image& test, const Image& reference, float fraction) {
  double mean = 0;
  const size_t pixels = reference.pixel_count();
  for (size_t p = 0; p < pixels; ++p) mean += luminance_at(reference, p);
  mean /= static_cast<double>(std::max<size_t>(pixels, 1));
  size_t dark = 0;
  for (size_t p = 0; p < pixels; ++p) {
    const float ref = luminance_at(reference, p);
    if (ref >= 0.01 * mean && luminance_at(test, p) < fraction * ref) ++dark;
  }
  return dark;
}

void run_adaptive_bench(const AdaptiveBenchSetup& b, const AdaptiveBenchPlan& plan) {
  std::printf("adaptive against uniform sampling: %s %dx%d, t = %g, filter %s\n", b.scene_name.c_str(), b.width,
              b.height, b.settings.threshold, filter_kind_name(b.settings.filter.kind));
  throughput_table(b, std::max(plan.rounds, 5));
  equal_time_table(b, plan);
  if (plan.clean_cap_s > 0) clean_table(b, plan.clean_cap_s);
  std::printf("\nwrote %s/adaptive_*_%s.{csv,svg,png}\n", b.out.c_str(), b.scene_name.c_str());
}

}  // namespace pxf
