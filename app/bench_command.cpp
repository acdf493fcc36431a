// pxf bench: run time against error (SPEC 4, issue 4 "Measured and reported"). Not a test: it
// prints figures and writes CSV and SVG plots into --out.
//   pxf bench                 per-stage times, filtering overhead, equal-time NRMSE, spp to match
//   pxf bench --pathtracer    paths/s, rays/s, ms/frame and the raw Embree ray rate
//   pxf bench --pathtracer --sampler-error | --variance-ratio   the samplers (app/sampler_bench.h)
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "app/commands.h"
#include "app/options.h"
#include "app/plot.h"
#include "app/sampler_bench.h"
#include "app/preview.h"
#include "gl/context.h"
#include "pathtracer/bench.h"

namespace pxf {

namespace {

using Clock = BenchClock;

bool is_power_of_two(int n) { return n > 0 && (n & (n - 1)) == 0; }

void write_text(const std::string& path, const std::string& text) {
  write_file_atomically(path, [&](const std::string& tmp) {
    std::ofstream out(tmp);
    out << text;
    if (!out) throw Error(path + ": cannot write");
  });
}

struct BenchSetup {
  Scene scene;
  PreviewSettings filtered, plain;
  int width = 0, height = 0;
  std::string out;
};

// The reference: a high-spp plain path tracing (independent seed), cached in the output folder.
Image obtain_reference(const BenchSetup& b, const std::string& given, int spp, const std::string& scene_name) {
  if (!given.empty()) return read_exr(given);
  const std::string base = std::filesystem::path(scene_name).stem().string();
  const std::string cache = b.out + "/reference_" + base + "_" + std::to_string(b.width) + "x" +
                            std::to_string(b.height) + "_" + std::to_string(spp) + "spp.exr";
  if (std::filesystem::exists(cache)) {
    std::printf("reference: %s (cached)\n", cache.c_str());
    return read_exr(cache);
  }
  TraceParams params = b.plain.trace;
  params.seed = b.plain.trace.seed + 7919;  // independent of the runs being judged
  ProgressiveRenderer renderer(b.scene, params, b.width, b.height);
  const auto start = Clock::now();
  for (int i = 0; i < spp; ++i) {
    renderer.add_frame();
    if ((i + 1) % 256 == 0 || i + 1 == spp)
      std::fprintf(stderr, "reference: %d/%d spp, %.0f s\n", i + 1, spp, elapsed_ms(start) / 1000);
  }
  Image reference = renderer.unfiltered_image();
  write_exr(cache, reference);
  std::printf("reference: wrote %s (%d spp, %.1f s)\n", cache.c_str(), spp, elapsed_ms(start) / 1000);
  return reference;
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
      const double e = compare_images(preview.renderer().unfiltered_image(), reference).nrmse_percent;
      measuring_ms += elapsed_ms(m0);
      run.spp.push_back(k);
      run.nrmse.push_back(e);
      run.nrmse_wall_ms.push_back(wall);
      if (k >= min_frames && e <= stop_nrmse) break;
    }
  }
  return run;
}

struct EqualTimeRow {
  int budget_frames = 0;
  double budget_ms = 0, plain_nrmse = 0;
  int filtered_frames = 0;
  double filtered_ms = 0, filtered_nrmse = 0;
};

// A filtered capture that stops adding frames when the next one (with its scheduled filter run)
// and the final filter + blend would exceed the budget; the actual wall time is reported.
EqualTimeRow run_equal_time(const BenchSetup& b, int budget_frames, double budget_ms, double pt_ms,
                            double filter_ms, double display_ms, const Image& reference) {
  Preview preview(b.scene, b.filtered, b.width, b.height);
  const auto start = Clock::now();
  for (int k = 1;; ++k) {
    preview.add_frame(false, false);
    // Frame k + 1 on a power of two runs the filter anyway, and then it is also the last frame's
    // filter run: finish() adds none. Otherwise finish() filters once more.
    const bool scheduled = is_power_of_two(k + 1);
    const double next = pt_ms + (scheduled ? filter_ms : 0.0);
    const double finish = (scheduled ? 0.0 : filter_ms) + display_ms;
    if (elapsed_ms(start) + next + finish > budget_ms) break;
  }
  preview.finish();
  EqualTimeRow row;
  row.budget_frames = budget_frames;
  row.budget_ms = budget_ms;
  row.filtered_frames = preview.samples();
  row.filtered_ms = elapsed_ms(start);
  row.filtered_nrmse = compare_images(preview.final_image(), reference).nrmse_percent;
  return row;
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

std::vector<int> parse_budgets(const std::string& text) {
  std::vector<int> budgets;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    char* end = nullptr;
    const long v = std::strtol(item.c_str(), &end, 10);
    if (item.empty() || *end || v < 1 || v > 1 << 16) throw UsageError("--budgets: '" + item + "' is not a frame count");
    budgets.push_back(static_cast<int>(v));
  }
  return budgets;
}

int run_pathtracer_bench(const BenchSetup& b, int timed) {
  const BenchResult r = run_benchmark(b.scene, b.width, b.height, b.plain.trace, 3, timed);
  std::printf("%s\n", format_benchmark(r).c_str());
  std::ostringstream csv;
  csv << "width,height,threads,max_vertices,timed_frames,paths_per_s,rays_per_s,rays_per_path,median_frame_ms,"
         "embree_rays_per_s,fraction_of_embree,embree_stream_rays_per_s,fraction_of_embree_stream,primary_ray_ms,"
         "primary_fraction\n"
      << r.width << "," << r.height << "," << r.threads << "," << r.max_vertices << "," << r.timed_frames << ","
      << r.paths_per_s << "," << r.rays_per_s << "," << r.rays_per_path << "," << r.median_frame_ms << ","
      << r.embree_rays_per_s << "," << r.fraction_of_embree << "," << r.embree_stream_rays_per_s << ","
      << r.fraction_of_embree_stream << "," << r.primary_ray_ms << "," << r.primary_fraction
      << "\n";
  write_text(b.out + "/pathtracer.csv", csv.str());
  std::printf("wrote %s/pathtracer.csv\n", b.out.c_str());
  return 0;
}

}  // namespace

int run_bench(const Args& args) {
  SceneOptions scene_options;
  PreviewOptions preview_options;
  bool pathtracer = false, sampler_error = false, variance_ratio = false;
  int seeds = 32, rounds = 7;
  std::string spp_text;
  std::string reference_path, out = "bench-out", budgets_text = "4,16,64";
  int reference_spp = 4096, frames = 32, max_spp = 1024, timed = 20;
  CommandLine cli("bench", "[options]",
                  "Run time against error on one scene (default cornell, 512x512, default settings):\n"
                  "  1. per-stage times of one scheduled filter application, in ms and in path-tracing frames;\n"
                  "  2. the relative overhead of filtering over --frames frames;\n"
                  "  3. NRMSE to the reference of unfiltered vs filtered images at equal wall time, at budgets of\n"
                  "     --budgets unfiltered frames;\n"
                  "  4. the spp at which unfiltered path tracing reaches the NRMSE of the filtered image at --frames.\n"
                  "The reference (--reference-spp plain path tracing) is cached in --out. Writes CSV and SVG plots.\n"
                  "--pathtracer instead measures paths/s, rays/s and the raw Embree incoherent-ray rate.");
  add_scene_options(cli, scene_options, /*headless=*/true);
  add_preview_options(cli, preview_options);
  cli.flag("--pathtracer", &pathtracer, "path tracer throughput only");
  cli.flag("--sampler-error", &sampler_error,
           "with --pathtracer: unfiltered NRMSE (and LV alone) of sobol vs independent at --spp against a "
           "--reference-spp Sobol reference of another seed, and paths/s of both back to back");
  cli.flag("--variance-ratio", &variance_ratio,
           "with --pathtracer: estimated / empirical Var[L_u] of the pixel mean over --seeds seeds at --spp");
  cli.option("--spp", &spp_text, "LIST", "spp of --sampler-error (default 8,32,128) or --variance-ratio (4,16,64,256)");
  cli.option("--seeds", &seeds, "seeds of --variance-ratio (default 32)", 2, 4096);
  cli.option("--rounds", &rounds, "timing rounds of --sampler-error (default 7)", 1, 1000);
  cli.option("--timed-frames", &timed, "timed frames of --pathtracer (after 3 warm-up frames)", 1, 100000);
  cli.option("--reference", &reference_path, "REF.exr", "reference image (default: render and cache one)");
  cli.option("--reference-spp", &reference_spp, "samples of the rendered reference (default 4096)", 1, 1 << 20);
  cli.option("--frames", &frames, "frames of the filtered run (default 32)", 1, 1 << 16);
  cli.option("--budgets", &budgets_text, "LIST", "equal-time budgets in unfiltered frames (default 4,16,64)");
  cli.option("--max-spp", &max_spp, "most unfiltered spp tried to match the filtered NRMSE (default 1024)", 1, 1 << 20);
  cli.option("--out", &out, "DIR", "folder for CSV, plots and the cached reference (default bench-out)");
  if (!cli.parse(args)) return 0;
  if (print_scene_list_if_asked(scene_options)) return 0;
  const std::vector<int> budgets = parse_budgets(budgets_text);

  BenchSetup b;
  b.scene = load_scene_for(scene_options, preview_options, cli);
  b.width = scene_options.width;
  b.height = scene_options.height;
  b.out = out;
  b.filtered = preview_options.settings;
  if (!b.filtered.filter_enabled) throw UsageError("--filter none: nothing to compare against");
  b.plain = b.filtered;
  b.plain.filter_enabled = false;
  std::filesystem::create_directories(out);
  if (pathtracer && (sampler_error || variance_ratio)) {
    SamplerBenchSetup sb{b.scene, std::filesystem::path(scene_options.scene).stem().string(), b.plain.trace, b.width,
                         b.height, out};
    if (sampler_error)
      run_sampler_error_bench(sb, cli.given("--reference-spp") ? reference_spp : 2048,
                              parse_budgets(spp_text.empty() ? "8,32,128" : spp_text), rounds);
    if (variance_ratio) run_variance_ratio_bench(sb, parse_budgets(spp_text.empty() ? "4,16,64,256" : spp_text), seeds);
    return 0;
  }
  if (pathtracer) return run_pathtracer_bench(b, timed);

  auto context = create_gl_context(parse_gl_backend(scene_options.gl));
  std::printf("bench: %s %dx%d, t=%g, filter %s, sigma_s=%g sigma_c=%g sigma_d=%g, GL %s (%s)\n",
              scene_options.scene.c_str(), b.width, b.height, b.filtered.threshold,
              filter_option_name(b.filtered).c_str(), b.filtered.filter.sigma_s, b.filtered.filter.sigma_c,
              b.filtered.filter.sigma_d, context->backend_name(), context->gl_renderer().c_str());
  const Image reference = obtain_reference(b, reference_path, reference_spp, scene_options.scene);
  if (reference.width != b.width || reference.height != b.height) throw Error("reference size differs from --size");

  // 1. Stage times.
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
  write_text(out + "/stages.csv", stages_csv.str());
  const double pt_ms = median_of(pt), filter_ms = median_of(filter_app), display_ms = median_of(display);
  const double range_ms = range.empty() ? 0 : range.front();
  std::printf("\n1. one scheduled filter application (median of %zu runs):\n", filter_app.size());
  std::printf("   path tracing frame %8.1f ms\n", pt_ms);
  std::printf("   upload + filter    %8.1f ms = %.2f path-tracing frames\n", filter_ms, filter_ms / pt_ms);
  std::printf("   blend + tone map   %8.1f ms = %.2f frames (every displayed frame)\n", display_ms, display_ms / pt_ms);
  std::printf("   range buffer       %8.1f ms = %.2f frames (once per camera change)\n", range_ms, range_ms / pt_ms);
  std::printf("   filter + range     %8.1f ms = %.2f frames (first application)\n", filter_ms + range_ms,
              (filter_ms + range_ms) / pt_ms);

  // 2 + 4. The unfiltered run: overhead and convergence.
  const int max_budget = *std::max_element(budgets.begin(), budgets.end());
  const PlainRun plain = run_plain(b, std::max({frames, max_budget, 64}), std::max({max_spp, max_budget, frames}),
                                   filtered.nrmse, reference);
  const double plain_frames_ms = plain.wall_ms[frames - 1];
  std::printf("\n2. overhead of filtering over %d frames: %.0f ms filtered vs %.0f ms unfiltered = %+.1f %% (%d filter runs)\n",
              frames, filtered.wall_ms, plain_frames_ms, 100.0 * (filtered.wall_ms / plain_frames_ms - 1.0),
              filtered.filter_runs);

  // 3. Equal time.
  std::printf("\n3. NRMSE to the reference at equal wall time:\n");
  std::printf("   budget  time ms  unfiltered NRMSE | filtered spp  time ms  NRMSE   ratio\n");
  std::ostringstream eq_csv;
  eq_csv << "budget_frames,budget_ms,unfiltered_nrmse_percent,filtered_spp,filtered_ms,filtered_nrmse_percent\n";
  PlotSeries filtered_points{"filtered (equal time)", {}, {}, true};
  for (int budget : budgets) {
    const double budget_ms = plain.wall_ms[budget - 1];
    double plain_nrmse = 0;
    for (size_t i = 0; i < plain.spp.size(); ++i)
      if (plain.spp[i] == budget) plain_nrmse = plain.nrmse[i];
    EqualTimeRow row = run_equal_time(b, budget, budget_ms, pt_ms, filter_ms, display_ms, reference);
    row.plain_nrmse = plain_nrmse;
    std::printf("   %6d %8.0f  %14.3f %%  | %12d %8.0f  %6.3f %%  %5.2fx\n", budget, budget_ms, plain_nrmse,
                row.filtered_frames, row.filtered_ms, row.filtered_nrmse, plain_nrmse / row.filtered_nrmse);
    eq_csv << budget << "," << budget_ms << "," << plain_nrmse << "," << row.filtered_frames << ","
           << row.filtered_ms << "," << row.filtered_nrmse << "\n";
    filtered_points.x.push_back(row.filtered_ms / 1000);
    filtered_points.y.push_back(row.filtered_nrmse);
  }
  write_text(out + "/equal_time.csv", eq_csv.str());

  const double match = spp_to_match(plain, filtered.nrmse);
  std::printf("\n4. filtered at %d spp: NRMSE %.3f %%; unfiltered reaches it at ", frames, filtered.nrmse);
  if (match > 0)
    std::printf("about %.0f spp\n", match);
  else
    std::printf("more than %d spp (%.3f %% there)\n", plain.spp.back(), plain.nrmse.back());

  std::ostringstream conv_csv;
  conv_csv << "spp,wall_ms,unfiltered_nrmse_percent\n";
  PlotSeries plain_curve{"unfiltered", {}, {}, false};
  for (size_t i = 0; i < plain.spp.size(); ++i) {
    conv_csv << plain.spp[i] << "," << plain.nrmse_wall_ms[i] << "," << plain.nrmse[i] << "\n";
    plain_curve.x.push_back(plain.nrmse_wall_ms[i] / 1000);
    plain_curve.y.push_back(plain.nrmse[i]);
  }
  write_text(out + "/convergence.csv", conv_csv.str());
  PlotSeries filtered_end{"filtered " + std::to_string(frames) + " spp", {filtered.wall_ms / 1000}, {filtered.nrmse}, true};
  write_svg_plot(out + "/nrmse_vs_time.svg",
                 {"NRMSE vs wall time: " + scene_options.scene, "wall time (s)", "NRMSE (%)", true, true},
                 {plain_curve, filtered_points, filtered_end});
  std::printf("\nwrote %s/stages.csv, equal_time.csv, convergence.csv, nrmse_vs_time.svg\n", out.c_str());
  return 0;
}

}  // namespace pxf
