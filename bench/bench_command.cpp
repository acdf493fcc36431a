// pxf bench: run time against error (README "Current figures", docs/measurements.md). Not a
// test: it prints figures and writes CSV and SVG plots into --out. One mode per run, named by the
// first argument (bench_modes() below: the default tables without a name, pathtracer,
// sampler-error, variance-ratio, variants, stage-table, threshold-fidelity, guiding-ab,
// guiding-bound, adaptive, demodulation-ab, motion); each mode is a small entry point over the
// shared harness (bench/bench_harness.h) that declares its own options and defaults.
#include "bench/bench_command.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "app/options.h"
#include "bench/adaptive_bench.h"
#include "bench/bench_harness.h"
#include "bench/bench_runs.h"
#include "bench/fidelity_bench.h"
#include "bench/files_bench.h"
#include "bench/guiding_bench.h"
#include "bench/motion_bench.h"
#include "bench/pathtracer_bench.h"
#include "bench/plot.h"
#include "bench/sampler_bench.h"
#include "gl/context.h"
#include "gl/cpu_reference.h"
#include "gl/filter_pass.h"
#include "image/metrics.h"
#include "preview/preview.h"

namespace pxf {

namespace {

using Clock = BenchClock;

// CSV columns beside the HDR NRMSE ones: "<prefix>display_nrmse_percent,<prefix>flip".
std::string display_csv_header(const std::string& prefix) {
  return prefix + "display_nrmse_percent," + prefix + "flip";
}
std::string display_csv(const RowError& e) {
  std::ostringstream s;
  s << e.display_nrmse << "," << e.flip;
  return s.str();
}

struct FilteredRun {
  std::vector<StageTimes> frames;  // per frame, the finish() included in the last one
  double wall_ms = 0;
  double nrmse = 0;
  int filter_runs = 0;
};

FilteredRun run_filtered(const BenchSetup& b, int frames, const Image& reference) {
  Preview preview(b.scene, b.filtered, b.width, b.height);
  FilteredRun run;
  const auto start = Clock::now();
  for (int i = 0; i < frames; ++i) {
    preview.add_frame(i + 1 == frames, false);
    run.frames.push_back(preview.last_times());
  }
  run.wall_ms = elapsed_ms(start);
  run.nrmse = compare_images(preview.final_image(), reference).nrmse_percent;
  run.filter_runs = preview.filter_runs();
  return run;
}

struct PlainRun {
  std::vector<double> wall_ms;  // after k+1 frames (display of the last frame included)
  std::vector<int> spp;         // where NRMSE was measured
  std::vector<double> nrmse;
  std::vector<RowError> errors;  // beside nrmse: display NRMSE and FLIP too
  std::vector<double> nrmse_wall_ms;
};

// Unfiltered progressive run; NRMSE every frame up to 64, then every 8th, until `stop_nrmse` is
// reached (after `min_frames`) or `max_frames`.
PlainRun run_plain(const BenchSetup& b, int min_frames, int max_frames, double stop_nrmse, const Image& reference) {
  Preview preview(b.scene, b.plain, b.width, b.height);
  PlainRun run;
  double measuring_ms = 0;  // time spent computing NRMSE is not part of the render
  const auto start = Clock::now();
  for (int k = 1; k <= max_frames; ++k) {
    preview.add_frame(false, false);
    preview.finish();  // blend + tone map of a displayed frame: what a viewer pays
    const double wall = elapsed_ms(start) - measuring_ms;
    run.wall_ms.push_back(wall);
    if (k <= 64 || k % 8 == 0) {
      const auto m0 = Clock::now();
      const RowError error = row_error(preview.renderer().unfiltered_image(), reference);
      const double e = error.hdr_nrmse;
      measuring_ms += elapsed_ms(m0);
      run.spp.push_back(k);
      run.nrmse.push_back(e);
      run.errors.push_back(error);
      run.nrmse_wall_ms.push_back(wall);
      if (k >= min_frames && e <= stop_nrmse) break;
    }
  }
  return run;
}

TimedRun run_timed(const BenchSetup& b, const PreviewSettings& settings, double budget_ms, const Image& reference) {
  return run_timed(b.scene, settings, b.width, b.height, budget_ms, reference);
}

struct EqualTimeRow {
  int budget_frames = 0;
  double budget_ms = 0;
  TimedRun filtered, plain;
};

EqualTimeRow run_equal_time(const BenchSetup& b, int budget_frames, double pt_ms, const Image& reference) {
  EqualTimeRow row;
  row.budget_frames = budget_frames;
  row.budget_ms = budget_frames * pt_ms;
  row.plain = run_timed(b, b.plain, row.budget_ms, reference);
  row.filtered = run_timed(b, b.filtered, row.budget_ms, reference);
  return row;
}

const char* kEqualTimeCsvHeader =
    "budget_frames,budget_ms,unfiltered_spp,unfiltered_ms,unfiltered_nrmse_percent,filtered_spp,filtered_ms,"
    "filtered_filter_runs,filtered_nrmse_percent,filtered_outside_tracing_share,unfiltered_display_nrmse_percent,"
    "unfiltered_flip,filtered_display_nrmse_percent,filtered_flip\n";

std::string equal_time_csv_row(const EqualTimeRow& r) {
  std::ostringstream line;
  line << r.budget_frames << "," << r.budget_ms << "," << r.plain.spp << "," << r.plain.used_ms << ","
       << r.plain.error.hdr_nrmse << "," << r.filtered.spp << "," << r.filtered.used_ms << ","
       << r.filtered.filter_runs << "," << r.filtered.error.hdr_nrmse << ","
       << share_outside_tracing(r.filtered.times, r.filtered.used_ms) << "," << display_csv(r.plain.error) << ","
       << display_csv(r.filtered.error) << "\n";
  return line.str();
}

// The spp at which plain path tracing reaches `target` NRMSE (log-log interpolation); 0 = never.
double spp_to_match(const PlainRun& run, double target) {
  for (size_t i = 0; i < run.nrmse.size(); ++i) {
    if (run.nrmse[i] > target) continue;
    if (i == 0) return run.spp[0];
    const double x0 = std::log(run.spp[i - 1]), x1 = std::log(run.spp[i]);
    const double y0 = std::log(run.nrmse[i - 1]), y1 = std::log(run.nrmse[i]), y = std::log(target);
    return std::exp(x0 + (y - y0) / (y1 - y0) * (x1 - x0));
  }
  return 0;
}

// A comma-separated list of counts in [1, 65536] (empty: none).
// One scene's row of the per-stage table: medians over `frames` frames of the
// scheduled run, and the overhead of the filtered run over the unfiltered one. The two runs advance
// frame by frame in turn, so that background load on a shared machine hits both alike.
struct StageRow {
  std::string scene;
  int width = 0, height = 0, filter_runs = 0;
  double pt_ms = 0, filter_ms = 0, range_ms = 0, display_ms = 0, filtered_ms = 0, plain_ms = 0;
  double overhead() const { return plain_ms > 0 ? filtered_ms / plain_ms - 1.0 : 0.0; }
};

StageRow measure_stages(const BenchSetup& b, const std::string& scene_name, int frames) {
  Preview filtered(b.scene, b.filtered, b.width, b.height);
  Preview plain(b.scene, b.plain, b.width, b.height);
  std::vector<double> pt, filter_app, display;
  StageRow row;
  for (int i = 0; i < frames; ++i) {
    const auto start = Clock::now();
    filtered.add_frame(i + 1 == frames, false);
    row.filtered_ms += elapsed_ms(start);
    const auto plain_start = Clock::now();
    plain.add_frame(i + 1 == frames, false);
    row.plain_ms += elapsed_ms(plain_start);
    const StageTimes& t = filtered.last_times();
    pt.push_back(t.path_tracing);
    if (t.filter > 0) filter_app.push_back(t.filter + t.upload);
    if (t.blend > 0) display.push_back(t.blend + t.tonemap);
    row.range_ms += t.range;
  }
  row.scene = scene_name;
  row.width = b.width;
  row.height = b.height;
  row.filter_runs = filtered.filter_runs();
  row.pt_ms = median_of(pt);
  row.filter_ms = median_of(filter_app);
  row.display_ms = median_of(display);
  return row;
}

int run_stage_table(SceneOptions scene_options, PreviewSettings preview_settings, const CommandLine& cli, int frames,
                    const std::string& out) {
  std::printf("per-stage ms over %d frames (scheduled filter runs), every built-in scene:\n", frames);
  std::printf("   %-10s %9s %8s %9s %8s %8s %5s %9s\n", "scene", "size", "PT ms", "filter", "range", "display",
              "runs", "overhead");
  std::ostringstream csv;
  csv << "scene,width,height,frames,path_tracing_ms,filter_ms,range_ms,blend_tonemap_ms,filter_runs,filtered_ms,"
         "unfiltered_ms,overhead_percent\n";
  PlotSeries overhead{"overhead over " + std::to_string(frames) + " frames", {}, {}, true};
  for (const BuiltinScene& builtin : builtin_scenes()) {
    SceneOptions so = scene_options;
    so.scene = builtin.name;
    if (!cli.given("--size")) so.width = so.height = 0;  // each scene's own default size
    BenchSetup b;
    b.filtered = preview_settings;
    b.scene = load_scene_for(so, b.filtered, cli);
    b.width = so.width;
    b.height = so.height;
    b.plain = b.filtered;
    b.plain.filter.kind = FilterKind::None;
    const StageRow r = measure_stages(b, builtin.name, frames);
    std::printf("   %-10s %4dx%-4d %8.1f %9.1f %8.1f %8.1f %5d %+8.1f %%\n", r.scene.c_str(), r.width, r.height,
                r.pt_ms, r.filter_ms, r.range_ms, r.display_ms, r.filter_runs, 100.0 * r.overhead());
    csv << r.scene << "," << r.width << "," << r.height << "," << frames << "," << r.pt_ms << "," << r.filter_ms << ","
        << r.range_ms << "," << r.display_ms << "," << r.filter_runs << "," << r.filtered_ms << "," << r.plain_ms
        << "," << 100.0 * r.overhead() << "\n";
    overhead.x.push_back(static_cast<double>(overhead.x.size() + 1));
    overhead.y.push_back(100.0 * r.overhead());
  }
  write_bench_text(out + "/stage_table.csv", csv.str());
  write_svg_plot(out + "/stage_overhead.svg",
                 {"filtering overhead per built-in scene (x: scene number, order of --scene list)", "scene",
                  "overhead (%)", false, false},
                 {overhead});
  std::printf("wrote %s/stage_table.csv, %s/stage_overhead.svg\n", out.c_str(), out.c_str());
  return 0;
}

int run_pathtracer_bench(const BenchSetup& b, int timed) {
  const BenchResult r = run_benchmark(b.scene, b.width, b.height, b.plain.trace, 3, timed);
  std::printf("%s\n", format_benchmark(r).c_str());
  write_bench_text(b.out + "/pathtracer.csv", benchmark_csv(r));
  std::printf("wrote %s/pathtracer.csv\n", b.out.c_str());
  return 0;
}

// The variant table: every filter variant applied to the same 4-spp HV
// buffer with the same converged range buffer: ms per application (median of `rounds` after one
// warm-up, the variants alternating so background load hits them alike), that in path-tracing
// frames (median of one frame per round, traced in the same run), and HV-only NRMSE against the
// reference's HV. Writes variants.csv, variants.svg and variant_<name>.png (the filtered HV,
// tone-mapped with the reference HV's log-average so they compare at one exposure).
// `extra_taps`: additional rows "subsampled-N" with N taps (to choose kSubsampledTaps).
int run_variant_bench(const BenchSetup& b, const Image& reference_hv, int spp, int rounds,
                      const std::vector<int>& extra_taps) {
  Preview preview(b.scene, b.filtered, b.width, b.height);
  if (reference_hv.width != b.width || reference_hv.height != b.height) throw Error("reference size differs from --size");
  double upload_ms = 0;  // of the inputs, before each filter run: the same for every variant
  for (int i = 0; i < spp; ++i) {
    preview.add_frame(i + 1 == spp, false);  // the last frame filters: uploads, converges the range buffer
    if (preview.last_times().upload > 0) upload_ms = preview.last_times().upload;
  }
  const Image hv = preview.inputs().hv_image();
  ProgressiveRenderer timing_tracer(b.scene, b.plain.trace, b.width, b.height);
  std::vector<std::string> names = filter_kind_names();
  std::vector<FilterParams> params;
  for (const std::string& name : names) {
    params.push_back(b.filtered.filter);
    params.back().kind = parse_filter_kind(name);
  }
  for (int taps : extra_taps) {
    names.push_back("subsampled-" + std::to_string(taps));
    params.push_back(b.filtered.filter);
    params.back().kind = FilterKind::Subsampled;
    params.back().subsampled_taps = taps;
  }
  FilterPass filter(b.width, b.height);
  std::vector<std::vector<double>> ms(names.size());
  std::vector<double> pt_ms;
  std::vector<Image> filtered(names.size());
  std::vector<uint32_t> filtered_pixels(names.size());
  std::array<std::vector<double>, 4> grid_step_ms;  // what the default variant's steps cost
  for (int round = -1; round < rounds; ++round) {
    const auto start = Clock::now();
    timing_tracer.add_frame();
    pt_ms.push_back(elapsed_ms(start));
    for (size_t k = 0; k < names.size(); ++k) {
      filter.run(preview.inputs(), preview.range().guide(), params[k], b.filtered.threshold, &preview.range().surface());
      if (round >= 0) ms[k].push_back(filter.last_ms());
      if (round >= 0 && params[k].kind == FilterKind::Grid)
        for (size_t i = 0; i < grid_step_ms.size(); ++i) grid_step_ms[i].push_back(filter.grid()->last_step_ms()[i]);
      if (round == 0) filtered[k] = filter.filtered_image(), filtered_pixels[k] = filter.filtered_pixels();
    }
  }
  const double frame_ms = median_of(pt_ms);
  TonemapParams tonemap;
  tonemap.log_average = static_cast<float>(cpu_log_average(reference_hv, tonemap.delta));
  write_png(b.out + "/variant_reference_hv.png", cpu_tonemap(reference_hv, tonemap));
  write_png(b.out + "/variant_unfiltered_hv.png", cpu_tonemap(hv, tonemap));
  const double unfiltered_nrmse = compare_images(hv, reference_hv).nrmse_percent;
  std::printf("\nvariants at %d spp (HV only, against the reference's HV; path-tracing frame %.1f ms, median of %zu;"
              " upload %.1f ms, the same for all):\n",
              spp, frame_ms, pt_ms.size(), upload_ms);
  std::printf("   %-16s %9s %9s %10s %10s %9s\n", "variant", "filter ms", "+upload", "PT frames", "NRMSE %", "filtered");
  std::printf("   %-16s %9s %9s %10s %10.2f\n", "unfiltered", "-", "-", "-", unfiltered_nrmse);
  std::ostringstream csv;
  csv << "variant,filter_ms,upload_ms,application_ms,pt_frame_ms,pt_frames,hv_nrmse_percent,filtered_pixels\n";
  csv << "unfiltered,0,0,0," << frame_ms << ",0," << unfiltered_nrmse << ",0\n";
  std::vector<PlotSeries> points;
  for (size_t k = 0; k < names.size(); ++k) {
    const double filter_ms = median_of(ms[k]), application_ms = filter_ms + upload_ms;
    const double nrmse = compare_images(filtered[k], reference_hv).nrmse_percent;
    std::printf("   %-16s %9.1f %9.1f %10.2f %10.2f %9u\n", names[k].c_str(), filter_ms, application_ms,
                application_ms / frame_ms, nrmse, filtered_pixels[k]);
    csv << names[k] << "," << filter_ms << "," << upload_ms << "," << application_ms << "," << frame_ms << ","
        << application_ms / frame_ms << "," << nrmse << "," << filtered_pixels[k] << "\n";
    points.push_back({names[k], {application_ms / frame_ms}, {nrmse}, true});
    write_png(b.out + "/variant_" + names[k] + ".png", cpu_tonemap(filtered[k], tonemap));
  }
  if (!grid_step_ms[0].empty()) {
    std::printf("   grid steps, median ms:");
    for (size_t i = 0; i < grid_step_ms.size(); ++i)
      std::printf(" %s %.1f", GridFilter::kStepNames[i], median_of(grid_step_ms[i]));
    std::printf("\n");
  }
  write_bench_text(b.out + "/variants.csv", csv.str());
  write_svg_plot(b.out + "/variants.svg",
                 {"Filter variants at " + std::to_string(spp) + " spp: HV-only NRMSE vs cost", "PT frames per application",
                  "HV NRMSE (%)", true, false},
                 points);
  std::printf("\nwrote %s/variants.csv, variants.svg, variant_<name>.png\n", b.out.c_str());
  return 0;
}

// Albedo demodulation off against on at equal wall time: per budget and round, unfiltered, filtered
// without and filtered with demodulation, back to back. Prints the display NRMSE ratios (median
// over rounds), writes demodulation.csv and the last round's images demod_<mode>_<budget>.png
// (tone-mapped with the reference's key and log-average, as the display metrics see them).
int run_demodulation_ab(const BenchSetup& b, const Image& reference, double pt_ms, const std::vector<int>& budgets,
                        int rounds) {
  PreviewSettings off = b.filtered, on = b.filtered;
  off.demodulate = false;
  on.demodulate = true;
  TonemapParams tonemap;
  tonemap.log_average = static_cast<float>(cpu_log_average(reference, tonemap.delta));
  write_png(b.out + "/demod_reference.png", cpu_tonemap(reference, tonemap));
  std::ostringstream csv;
  csv << "budget_frames,round,unfiltered_spp,unfiltered_display_nrmse_percent,unfiltered_flip,off_spp,"
         "off_display_nrmse_percent,off_flip,on_spp,on_display_nrmse_percent,on_flip\n";
  std::printf("\nalbedo demodulation at equal wall time (median of %d rounds; display NRMSE, filtered / unfiltered):\n",
              rounds);
  std::printf("   budget | unfiltered spp  display | demod off spp  display  ratio | demod on spp  display  ratio\n");
  for (int budget : budgets) {
    std::vector<double> plain_e, off_e, on_e, off_ratio, on_ratio, plain_spp, off_spp, on_spp;
    for (int round = 0; round < rounds; ++round) {
      const double budget_ms = budget * pt_ms;
      const TimedRun u = run_timed(b, b.plain, budget_ms, reference);
      const TimedRun f0 = run_timed(b, off, budget_ms, reference);
      const TimedRun f1 = run_timed(b, on, budget_ms, reference);
      csv << budget << "," << round << "," << u.spp << "," << display_csv(u.error) << "," << f0.spp << ","
          << display_csv(f0.error) << "," << f1.spp << "," << display_csv(f1.error) << "\n";
      plain_e.push_back(u.error.display_nrmse), off_e.push_back(f0.error.display_nrmse), on_e.push_back(f1.error.display_nrmse);
      off_ratio.push_back(f0.error.display_nrmse / u.error.display_nrmse);
      on_ratio.push_back(f1.error.display_nrmse / u.error.display_nrmse);
      plain_spp.push_back(u.spp), off_spp.push_back(f0.spp), on_spp.push_back(f1.spp);
      if (round + 1 == rounds) {
        const std::string suffix = "_" + std::to_string(budget) + ".png";
        write_png(b.out + "/demod_unfiltered" + suffix, cpu_tonemap(u.image, tonemap));
        write_png(b.out + "/demod_off" + suffix, cpu_tonemap(f0.image, tonemap));
        write_png(b.out + "/demod_on" + suffix, cpu_tonemap(f1.image, tonemap));
      }
    }
    std::printf("   %6d | %14.0f  %6.2f %% | %13.0f  %6.2f %%  %5.2fx | %12.0f  %6.2f %%  %5.2fx\n", budget,
                median_of(plain_spp), median_of(plain_e), median_of(off_spp), median_of(off_e), median_of(off_ratio),
                median_of(on_spp), median_of(on_e), median_of(on_ratio));
  }
  write_bench_text(b.out + "/demodulation.csv", csv.str());
  std::printf("\nwrote %s/demodulation.csv, demod_<unfiltered|off|on>_<budget>.png\n", b.out.c_str());
  return 0;
}



// The default mode's tables 1-4 (see its --help).
int run_time_tables(const BenchSetup& b, const Image& reference, int frames, const std::vector<int>& budgets,
                    int max_spp) {
  // 1. Stage times. llvmpipe compiles each shader at its first draw: a warm-up run filters twice
  // first, so that the figures are what a later filter run or a camera change costs.
  {
    PreviewSettings warm_settings = b.filtered;
    warm_settings.schedule = FilterSchedule::EveryFrame;
    Preview warm(b.scene, warm_settings, b.width, b.height);
    warm.add_frame(false, true);
    warm.add_frame(true, true);
  }
  const FilteredRun filtered = run_filtered(b, frames, reference);
  std::vector<double> pt, filter_app, range, display;
  std::ostringstream stages_csv;
  stages_csv << "frame,path_tracing_ms,upload_ms,range_ms,filter_ms,blend_ms,tonemap_ms\n";
  for (size_t i = 0; i < filtered.frames.size(); ++i) {
    const StageTimes& t = filtered.frames[i];
    stages_csv << i + 1 << "," << t.path_tracing << "," << t.upload << "," << t.range << "," << t.filter << ","
               << t.blend << "," << t.tonemap << "\n";
    pt.push_back(t.path_tracing);
    if (t.filter > 0) filter_app.push_back(t.filter + t.upload), range.push_back(t.range);
    if (t.blend > 0) display.push_back(t.blend + t.tonemap);
  }
  write_bench_text(b.out + "/stages.csv", stages_csv.str());
  const double pt_ms = median_of(pt), filter_ms = median_of(filter_app), display_ms = median_of(display);
  const double range_ms = range.empty() ? 0 : range.front();
  std::printf("\n1. one scheduled filter application (median of %zu runs, after a warm-up that compiled the shaders):\n", filter_app.size());
  std::printf("   path tracing frame %8.1f ms\n", pt_ms);
  std::printf("   upload + filter    %8.1f ms = %.2f path-tracing frames\n", filter_ms, filter_ms / pt_ms);
  std::printf("   blend + tone map   %8.1f ms = %.2f frames (every displayed frame)\n", display_ms, display_ms / pt_ms);
  std::printf("   range buffer       %8.1f ms = %.2f frames (once per camera change)\n", range_ms, range_ms / pt_ms);
  std::printf("   filter + range     %8.1f ms = %.2f frames (first application)\n", filter_ms + range_ms,
              (filter_ms + range_ms) / pt_ms);

  // 2 + 4. The unfiltered run: overhead and convergence.
  const PlainRun plain = run_plain(b, std::max(frames, 64), std::max(max_spp, frames),
                                   filtered.nrmse, reference);
  const double plain_frames_ms = plain.wall_ms[frames - 1];
  std::printf("\n2. overhead of filtering over %d frames: %.0f ms filtered vs %.0f ms unfiltered = %+.1f %% (%d filter runs)\n",
              frames, filtered.wall_ms, plain_frames_ms, 100.0 * (filtered.wall_ms / plain_frames_ms - 1.0),
              filtered.filter_runs);

  // 3. Equal time: both runs under the same --time budget of N median path-tracing frames.
  std::printf("\n3. HDR NRMSE to the reference at equal wall time of the whole job (--time = N PT frames):\n");
  std::printf("   budget  time ms | unfiltered spp  used ms  NRMSE   | filtered spp  used ms  NRMSE    ratio"
              " | display NRMSE unf / filt (ratio)  FLIP unf / filt\n");
  std::ostringstream eq_csv;
  eq_csv << kEqualTimeCsvHeader;
  PlotSeries filtered_points{"filtered (--time)", {}, {}, true};
  PlotSeries plain_points{"unfiltered (--time)", {}, {}, true};
  for (int budget : budgets) {
    const EqualTimeRow row = run_equal_time(b, budget, pt_ms, reference);
    const RowError& u = row.plain.error;
    const RowError& f = row.filtered.error;
    std::printf("   %6d %8.0f | %14d %8.0f  %6.3f %% | %12d %8.0f  %6.3f %%  %5.2fx | %7.3f %% / %7.3f %% (%.2fx)  %.4f / %.4f\n",
                budget, row.budget_ms, row.plain.spp, row.plain.used_ms, u.hdr_nrmse, row.filtered.spp,
                row.filtered.used_ms, f.hdr_nrmse, f.hdr_nrmse / u.hdr_nrmse, u.display_nrmse, f.display_nrmse,
                f.display_nrmse / u.display_nrmse, u.flip, f.flip);
    eq_csv << equal_time_csv_row(row);
    filtered_points.x.push_back(row.filtered.used_ms / 1000);
    filtered_points.y.push_back(row.filtered.error.hdr_nrmse);
    plain_points.x.push_back(row.plain.used_ms / 1000);
    plain_points.y.push_back(row.plain.error.hdr_nrmse);
  }
  write_bench_text(b.out + "/equal_time.csv", eq_csv.str());

  const double match = spp_to_match(plain, filtered.nrmse);
  std::printf("\n4. filtered at %d spp: NRMSE %.3f %%; unfiltered reaches it at ", frames, filtered.nrmse);
  if (match > 0)
    std::printf("about %.0f spp\n", match);
  else
    std::printf("more than %d spp (%.3f %% there)\n", plain.spp.back(), plain.nrmse.back());

  std::ostringstream conv_csv;
  conv_csv << "spp,wall_ms,unfiltered_nrmse_percent," << display_csv_header("unfiltered_") << "\n";
  PlotSeries plain_curve{"unfiltered", {}, {}, false};
  for (size_t i = 0; i < plain.spp.size(); ++i) {
    conv_csv << plain.spp[i] << "," << plain.nrmse_wall_ms[i] << "," << plain.nrmse[i] << ","
             << display_csv(plain.errors[i]) << "\n";
    plain_curve.x.push_back(plain.nrmse_wall_ms[i] / 1000);
    plain_curve.y.push_back(plain.nrmse[i]);
  }
  write_bench_text(b.out + "/convergence.csv", conv_csv.str());
  PlotSeries filtered_end{"filtered " + std::to_string(frames) + " spp", {filtered.wall_ms / 1000}, {filtered.nrmse}, true};
  write_svg_plot(b.out + "/nrmse_vs_time.svg",
                 {"NRMSE vs wall time: " + b.scene_name, "wall time (s)", "NRMSE (%)", true, true},
                 {plain_curve, plain_points, filtered_points, filtered_end});
  std::printf("\nwrote %s/stages.csv, equal_time.csv, convergence.csv, nrmse_vs_time.svg\n", b.out.c_str());
  return 0;
}

// --- The modes: each a small entry point over the shared harness (bench/bench_harness.h), with its
// own options and defaults.

int time_mode(const Args& args, const std::string& summary) {
  BenchHarness h("", summary);
  int frames = 32, max_spp = 1024;
  std::string budgets_text = "8,32,128,256";
  h.add_reference_options(2048);
  h.cli().option("--frames", &frames, "frames of the filtered run (default 32)", 1, 1 << 16);
  h.cli().option("--budgets", &budgets_text, "LIST", "equal-time budgets in median path-tracing frames (default 8,32,128,256)");
  h.cli().option("--max-spp", &max_spp, "most unfiltered spp tried to match the filtered NRMSE (default 1024)", 1, 1 << 20);
  if (!h.parse(args)) return 0;
  const std::vector<int> budgets = parse_counts("--budgets", budgets_text);
  const BenchSetup b = h.setup(/*needs_filter=*/true);
  auto context = h.gl_context();
  std::printf("bench: %s %dx%d, t=%g, filter %s, sigma_s=%g sigma_c=%g sigma_d=%g, GL %s (%s)\n",
              h.scene_options().scene.c_str(), b.width, b.height, b.filtered.threshold,
              filter_kind_name(b.filtered.filter.kind), b.filtered.filter.sigma_s, b.filtered.filter.sigma_c,
              b.filtered.filter.sigma_d, context->backend_name(), context->gl_renderer().c_str());
  return run_time_tables(b, h.reference(b), frames, budgets, max_spp);
}

int pathtracer_mode(const Args& args, const std::string& summary) {
  BenchHarness h("pathtracer", summary);
  int timed = 20;
  h.cli().option("--timed-frames", &timed, "timed frames (after 3 warm-up frames; default 20)", 1, 100000);
  if (!h.parse(args)) return 0;
  return run_pathtracer_bench(h.setup(/*needs_filter=*/false), timed);
}

SamplerBenchSetup sampler_setup(const BenchSetup& b) {
  return SamplerBenchSetup{b.scene, b.scene_name, b.plain.trace, b.width, b.height, b.out};
}

int sampler_error_mode(const Args& args, const std::string& summary) {
  BenchHarness h("sampler-error", summary);
  std::string spp_text = "8,32,128";
  int seeds = 8, rounds = 7, reference_spp = 2048;
  h.cli().option("--spp", &spp_text, "LIST", "sample counts (default 8,32,128)");
  h.cli().option("--seeds", &seeds, "seeds (default 8)", 2, 4096);
  h.cli().option("--rounds", &rounds, "rounds of the paths/s comparison (default 7)", 1, 1000);
  h.cli().option("--reference-spp", &reference_spp, "samples of the Sobol reference of another seed (default 2048)", 1, 1 << 20);
  if (!h.parse(args)) return 0;
  run_sampler_error_bench(sampler_setup(h.setup(/*needs_filter=*/false)), reference_spp, parse_counts("--spp", spp_text),
                          rounds, seeds);
  return 0;
}

int variance_ratio_mode(const Args& args, const std::string& summary) {
  BenchHarness h("variance-ratio", summary);
  std::string spp_text = "4,16,64,256";
  int seeds = 32;
  h.cli().option("--spp", &spp_text, "LIST", "sample counts (default 4,16,64,256)");
  h.cli().option("--seeds", &seeds, "seeds (default 32)", 2, 4096);
  if (!h.parse(args)) return 0;
  run_variance_ratio_bench(sampler_setup(h.setup(/*needs_filter=*/false)), parse_counts("--spp", spp_text), seeds);
  return 0;
}

int variants_mode(const Args& args, const std::string& summary) {
  BenchHarness h("variants", summary);
  int variant_spp = 4, variant_rounds = 5;
  std::string extra_taps_text;
  h.add_reference_options(2048);
  h.cli().option("--variant-spp", &variant_spp, "spp of the HV buffer (default 4)", 1, 1 << 16);
  h.cli().option("--variant-rounds", &variant_rounds, "timed rounds (default 5, after a warm-up)", 1, 1000);
  h.cli().option("--subsampled-taps", &extra_taps_text, "LIST", "also the subsampled variant with these tap counts");
  if (!h.parse(args)) return 0;
  const std::vector<int> extra_taps = parse_counts("--subsampled-taps", extra_taps_text);
  const BenchSetup b = h.setup(/*needs_filter=*/true);
  auto context = h.gl_context();
  return run_variant_bench(b, h.reference(b, "hv"), variant_spp, variant_rounds, extra_taps);
}

int stage_table_mode(const Args& args, const std::string& summary) {
  BenchHarness h("stage-table", summary);
  int frames = 32;
  h.cli().option("--frames", &frames, "frames per scene (default 32)", 1, 1 << 16);
  if (!h.parse(args)) return 0;
  if (!h.settings().filtering()) throw UsageError("--filter none: nothing to compare against");
  const std::string out = h.setup(/*needs_filter=*/true).out;  // validates the options and creates --out
  auto context = h.gl_context();
  return run_stage_table(h.scene_options(), h.settings(), h.cli(), frames, out);
}

int threshold_fidelity_mode(const Args& args, const std::string& summary) {
  BenchHarness h("threshold-fidelity", summary);
  std::string spp_text = "16,64,256";
  int seeds = 32;
  h.cli().option("--spp", &spp_text, "LIST", "sample counts (default 16,64,256)");
  h.cli().option("--seeds", &seeds, "seeds (default 32)", 2, 4096);
  AdaptiveGoal goal = AdaptiveGoal::Error;
  h.cli().choice("--goal", &goal, {"error", "clean"},
                 "the adaptive allocation's goal: least error (a render to a count or time, the default) or "
                 "clean (--until-clean's)");
  if (!h.parse(args)) return 0;
  const BenchSetup b = h.setup(/*needs_filter=*/true);
  auto context = h.gl_context();
  FidelityBenchSetup fb{b.scene, b.scene_name, b.filtered, b.width, b.height, b.out};
  fb.with_adaptive = b.filtered.adaptive;  // --adaptive on: also adaptive sampling, at the uniform job's wall time
  fb.settings.adaptive_params.goal = goal;
  const std::vector<float> thresholds =
      h.cli().given("--threshold") ? std::vector<float>{b.filtered.threshold} : std::vector<float>{0.001f, 0.01f};
  run_threshold_fidelity_bench(fb, parse_counts("--spp", spp_text), thresholds, seeds);
  return 0;
}

int guiding_mode(const Args& args, const std::string& summary) {
  BenchHarness h("guiding-ab", summary);
  GuidingBenchPlan plan;
  plan.rounds = 5;
  plan.cost_frames = 32;
  std::string budgets_text = "2,8";
  h.add_reference_options(2048);
  h.cli().option("--budgets", &budgets_text, "LIST", "equal-time budgets in seconds (default 2,8)");
  h.cli().option("--rounds", &plan.rounds, "alternating rounds (default 5)", 1, 1000);
  h.cli().option("--frames", &plan.cost_frames, "frames of the equal-spp cost comparison (default 32)", 1, 1 << 16);
  if (!h.parse(args)) return 0;
  plan.budgets_s = parse_counts("--budgets", budgets_text);
  const BenchSetup b = h.setup(/*needs_filter=*/false);
  run_guiding_bench({b.scene, b.plain.trace, b.width, b.height, b.out, h.reference(b)}, plan);
  return 0;
}

int guiding_bound_mode(const Args& args, const std::string& summary) {
  BenchHarness h("guiding-bound", summary);
  GuidingBoundSettings settings;
  h.cli().option("--points", &settings.points, "first vertices (default 48)", 1, 100000);
  h.cli().option("--cells", &settings.face_cells, "cells along a cube face's edge (default 24; even)", 2, 512);
  h.cli().option("--paths", &settings.paths_per_cell, "paths per cell (default 32)", 1, 1 << 20);
  h.cli().option("--frames", &settings.train_frames, "frames of the field's training (default 31)", 1, 1 << 16);
  h.cli().option("--floor-directions", &settings.floor_directions, "directions per point for the floor (default 256)", 1,
                 1 << 20);
  h.cli().option("--floor-paths", &settings.floor_paths, "paths in each of them (default 256)", 2, 1 << 16);
  int lv_hv_spp = 32;
  h.cli().option("--spp", &lv_hv_spp, "samples of the two renders that split the error into LV and HV (default 32)", 1,
                 1 << 16);
  if (!h.parse(args)) return 0;
  if (settings.face_cells % 2 != 0) throw UsageError("--cells must be even (a side face's upper half is traced)");
  const BenchSetup b = h.setup(/*needs_filter=*/false);
  settings.seed = b.plain.trace.seed;
  run_guiding_bound_bench({b.scene, b.plain.trace, b.width, b.height, b.out, lv_hv_spp}, settings);
  return 0;
}

int adaptive_mode(const Args& args, const std::string& summary) {
  BenchHarness h("adaptive", summary);
  AdaptiveBenchPlan plan;
  plan.rounds = 3;
  plan.clean_cap_s = 300;
  std::string budgets_text = "8,32,128,512";
  h.add_reference_options(2048);
  h.cli().option("--budgets", &budgets_text, "LIST", "equal-time budgets in median path-tracing frames (default 8,32,128,512)");
  h.cli().option("--rounds", &plan.rounds, "alternating rounds (default 3)", 1, 1000);
  h.cli().option("--clean-cap", &plan.clean_cap_s, "seconds of each until-clean run (default 300; 0: none)", 0.0, 1e6);
  if (!h.parse(args)) return 0;
  plan.budgets = parse_counts("--budgets", budgets_text);
  const BenchSetup b = h.setup(/*needs_filter=*/true);
  auto context = h.gl_context();
  run_adaptive_bench({b.scene, b.scene_name, b.filtered, b.width, b.height, b.out, h.reference(b)}, plan);
  return 0;
}

int demodulation_mode(const Args& args, const std::string& summary) {
  BenchHarness h("demodulation-ab", summary);
  int rounds = 3;
  std::string budgets_text = "8,32,128,256";
  h.add_reference_options(2048);
  h.cli().option("--budgets", &budgets_text, "LIST", "equal-time budgets in median path-tracing frames (default 8,32,128,256)");
  h.cli().option("--rounds", &rounds, "rounds, back to back with the unfiltered run (default 3)", 1, 1000);
  if (!h.parse(args)) return 0;
  const std::vector<int> budgets = parse_counts("--budgets", budgets_text);
  const BenchSetup b = h.setup(/*needs_filter=*/true);
  auto context = h.gl_context();
  const Image reference = h.reference(b);
  // The budgets' unit: the median path-tracing frame of a short unfiltered warm-up.
  Preview warm(b.scene, b.plain, b.width, b.height);
  std::vector<double> frame_ms;
  for (int i = 0; i < 8; ++i) {
    warm.add_frame(i == 7, i == 7);
    frame_ms.push_back(warm.last_times().path_tracing);
  }
  return run_demodulation_ab(b, reference, median_of(frame_ms), budgets, rounds);
}

int motion_mode(const Args& args, const std::string& summary) {
  BenchHarness h("motion", summary);
  int frames = 60, reference_spp = 1024;
  double orbit_degrees = 90;
  h.cli().option("--motion-frames", &frames, "frames of the orbit (default 60)", 2, 100000);
  h.cli().option("--orbit-degrees", &orbit_degrees, "the whole orbit in degrees (default 90)", 0.0, 3600.0);
  h.cli().option("--reference-spp", &reference_spp, "samples of each frame's reference (default 1024)", 1, 1 << 20);
  std::string camera_path;
  h.cli().option("--camera-path", &camera_path, "FILE.json|turntable:N",
                 "the views of a camera path (keyframes, as pxf render --camera-path) instead of the orbit");
  bool one_reference = false;
  h.cli().flag("--one-reference", &one_reference,
               "no second reference per frame (halves the references' time; the error is then not corrected "
               "for the references' own noise)");
  if (!h.parse(args)) return 0;
  const BenchSetup b = h.setup(/*needs_filter=*/true);
  auto context = h.gl_context();
  MotionBenchSetup mb{b.scene, h.scene_options().scene, b.filtered, b.width, b.height, b.out};
  mb.frames = frames;
  mb.orbit_degrees = static_cast<float>(orbit_degrees);
  mb.reference_spp = reference_spp;
  mb.second_reference = !one_reference;
  mb.camera_path = camera_path;
  run_motion_bench(mb);
  return 0;
}

struct BenchMode {
  const char* name;  // "" the default mode
  const char* brief;  // one line for the list of modes
  const char* summary;
  int (*run)(const Args& args, const std::string& summary);
};

const std::vector<BenchMode>& bench_modes() {
  static const std::vector<BenchMode> modes{
      {"", "per-stage times, filtering overhead, equal-time NRMSE, spp to match", "run time against error on one scene (default cornell at its size, default settings):\n"
           "  1. per-stage times of one scheduled filter application, in ms and in path-tracing frames;\n"
           "  2. the relative overhead of filtering over --frames frames;\n"
           "  3. NRMSE to the reference of unfiltered vs filtered images at equal wall time of the whole job\n"
           "     (the --time machinery), at budgets of --budgets median path-tracing frames, in HDR and on\n"
           "     display values (both tone-mapped with the reference's key and log-average), with the mean\n"
           "     LDR-FLIP of the display images;\n"
           "  4. the spp at which unfiltered path tracing reaches the NRMSE of the filtered image at --frames.\n"
           "The reference (--reference-spp plain path tracing) is cached in --out. Writes CSV and SVG plots.",
       time_mode},
      {"pathtracer", "path tracer throughput against raw Embree on the same rays",
       "path tracer throughput: paths/s, rays/s and ms/frame over --timed-frames frames (after 3 warm-up frames),\n"
       "against raw Embree on the same rays: the frame after the warm-up is recorded (every closest-hit and\n"
       "shadow ray the tracer hands to Embree, with its tmin/tmax and call) and replayed on the tracer's own\n"
       "Embree scene with as many threads, both as traced (its streams as rtcIntersect1M / rtcOccluded1M of the\n"
       "same sizes) and one ray per call (rtcIntersect1 / rtcOccluded1), once after each of max(5, frames / 4)\n"
       "blocks of the timed frames, the median: rays/s of each, split closest-hit / shadow, and the tracer's\n"
       "rays/s as a fraction of each. Then the median time of a frame cut to primary rays. Writes\n"
       "pathtracer.csv into --out.",
       pathtracer_mode},
      {"sampler-error", "Sobol against independent numbers: error and speed",
       "unfiltered NRMSE (and LV alone) of sobol vs independent at --spp against a Sobol reference of another\n"
       "seed, and paths/s of both back to back (bench/sampler_bench.h)",
       sampler_error_mode},
      {"variance-ratio", "the estimated against the empirical variance of the mean", "estimated / empirical Var[L_u] of the pixel mean over --seeds seeds at --spp (bench/sampler_bench.h)",
       variance_ratio_mode},
      {"variants", "every filter variant: time against HV error",
       "every filter variant on one --variant-spp HV buffer: ms per application, path-tracing frames, HV-only\n"
       "NRMSE against the reference's HV (layer hv of --reference, e.g. buffers.exr of `pxf render --filter\n"
       "none`; default: rendered and cached)",
       variants_mode},
      {"stage-table", "per-stage times of every built-in scene", "per-stage ms and overhead over --frames frames for every built-in scene (no reference)",
       stage_table_mode},
      {"threshold-fidelity", "the blend's threshold against the empirical perceived variance",
       "empirical perceived variance of the final image over --seeds seeds at --spp against --threshold\n"
       "(default both t = 0.001 and 0.01), by blend case (the --filter's; bilateral and bilateral-depth give\n"
       "the blend the covariance of L_u and L_f); with --adaptive on also adaptive sampling at the uniform\n"
       "job's wall time (bench/fidelity_bench.h)",
       threshold_fidelity_mode},
      {"guiding-ab", "path guiding against none at equal time",
       "path guiding against none, unfiltered (bench/guiding_bench.h): ms per frame at equal spp (--frames), and\n"
       "HDR and display NRMSE at equal wall time of --budgets seconds, median of --rounds alternating rounds",
       guiding_mode},
      {"guiding-bound", "how far first-vertex guiding can go: the field against the light known exactly",
       "at --points first vertices drawn over the image (bench/guiding_bench.h, bench/guiding_bound.h): the\n"
       "variance of the indirect light's estimate under cosine sampling, the field trained for --frames frames,\n"
       "the light known exactly (from --paths paths in each of the hemisphere's cells), the least any choice of\n"
       "cells gives, and a floor under every guide, however fine (from --floor-paths paths in each of\n"
       "--floor-directions exact directions); per point and summed, then what the floor means for the image's\n"
       "HDR error (the LV/HV split of two --spp renders' error)",
       guiding_bound_mode},
      {"adaptive", "adaptive against uniform sampling: equal time, time to clean, throughput",
       "adaptive against uniform sampling, both filtered (bench/adaptive_bench.h): paths/s at 100/50/10 %\n"
       "active pixels, display and HDR NRMSE at equal wall time (--budgets, --rounds), starved dark pixels,\n"
       "and the clean share over time up to --clean-cap",
       adaptive_mode},
      {"demodulation-ab", "albedo demodulation off against on at equal time",
       "albedo demodulation off vs on at equal wall time (--budgets, --rounds rounds, back to back with the\n"
       "unfiltered run); writes demodulation.csv and demod_*.png",
       demodulation_mode},
      {"motion", "a camera orbit: reprojected history against restarts",
       "a camera orbit of --motion-frames frames over --orbit-degrees, one path per pixel per frame, with the\n"
       "reprojected history and the filter every frame against restart + unfiltered at equal frame time:\n"
       "error, flicker, disocclusions, frame times (bench/motion_bench.h)",
       motion_mode},
      {"files", "the equal-time table over a list of scene files, each with its light",
       "for each file of --list (one 'NAME SCENE [ENV]' a line) and each --times budget in seconds: plain\n"
       "path tracing against the preview at equal wall time of the whole job (the file's load taken off both),\n"
       "--rounds alternating rounds, display and HDR NRMSE and LDR-FLIP against a --reference-spp reference of\n"
       "another seed (cached in --out), and the preview's bias (its mean against the unfiltered mean of its own\n"
       "samples); writes files.csv and files_sheet.png (bench/files_bench.h)",
       files_bench_mode},
  };
  return modes;
}

// The default mode's --help: its own text, then the other modes.
std::string default_summary() {
  std::string text = bench_modes()[0].summary;
  text += "\n\nOther modes (`pxf bench MODE --help` for each one's options):";
  for (size_t i = 1; i < bench_modes().size(); ++i) {
    char line[160];
    std::snprintf(line, sizeof line, "\n  %-20s %s", bench_modes()[i].name, bench_modes()[i].brief);
    text += line;
  }
  return text;
}

}  // namespace

// The mode is the first argument when it does not start with '-' (none: the default mode); it gets
// the other arguments. A leading --NAME of a mode that is no option reads as NAME: the spelling of
// earlier builds, which scripts still use.
int run_bench(const Args& args) {
  const std::string name = args.empty() ? "" : args[0];
  for (size_t i = 1; i < bench_modes().size(); ++i)
    if (name == bench_modes()[i].name) return bench_modes()[i].run(Args(args.begin() + 1, args.end()), bench_modes()[i].summary);
  if (!args.empty() && args[0].rfind("-", 0) != 0)
    throw UsageError("unknown mode '" + args[0] + "' (pxf bench --help lists the modes)");
  return bench_modes()[0].run(args, default_summary());
}

}  // namespace pxf
