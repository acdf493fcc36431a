// pxf bench: run time against error (SPEC 4, issue 4 "Measured and reported"). Not a test: it
// prints figures and writes CSV and SVG plots into --out.
//   pxf bench                 per-stage times, filtering overhead, equal-time NRMSE, spp to match
//   pxf bench --pathtracer    paths/s, rays/s, ms/frame and the raw Embree ray rate
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
#include "app/preview.h"
#include "gl/context.h"
#include "pathtracer/bench.h"

namespace pxf {

namespace {

using Clock = BenchClock;

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

// One job under `--time` (the render command's machinery): frames while the next one, its due
// passes and the finish fit the budget, then the finish. One row of the equal-time table; columns
// are added per row.
struct TimedRun {
  int spp = 0;
  double used_ms = 0;
  int filter_runs = 0;
  StageTimes times;
  ImageMetrics metrics;
};

TimedRun run_timed(const BenchSetup& b, const PreviewSettings& settings, double budget_ms, const Image& reference) {
  const auto start = Clock::now();
  Preview preview(b.scene, settings, b.width, b.height);
  for (int i = 0;; ++i) {
    if (i > 0 && !next_frame_fits(preview.predict_next_frame(budget_ms, elapsed_ms(start)))) break;
    preview.add_frame(false, /*display=*/i == 0);  // the first display measures the finish's
  }
  preview.finish();
  TimedRun run;
  run.used_ms = elapsed_ms(start);
  run.spp = preview.samples();
  run.filter_runs = preview.filter_runs();
  run.times = preview.total_times();
  run.metrics = compare_images(preview.final_image(), reference);
  return run;
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
    "filtered_filter_runs,filtered_nrmse_percent,filtered_outside_tracing_share\n";

std::string equal_time_csv_row(const EqualTimeRow& r) {
  std::ostringstream line;
  line << r.budget_frames << "," << r.budget_ms << "," << r.plain.spp << "," << r.plain.used_ms << ","
       << r.plain.metrics.nrmse_percent << "," << r.filtered.spp << "," << r.filtered.used_ms << ","
       << r.filtered.filter_runs << "," << r.filtered.metrics.nrmse_percent << ","
       << share_outside_tracing(r.filtered.times, r.filtered.used_ms) << "\n";
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

// One scene's row of the per-stage table (thesis Table 3.2): medians over `frames` frames of the
// scheduled run, and the overhead of the filtered run over the unfiltered one.
struct StageRow {
  std::string scene;
  int width = 0, height = 0, filter_runs = 0;
  double pt_ms = 0, filter_ms = 0, range_ms = 0, display_ms = 0, filtered_ms = 0, plain_ms = 0;
  double overhead() const { return plain_ms > 0 ? filtered_ms / plain_ms - 1.0 : 0.0; }
};

StageRow measure_stages(const BenchSetup& b, const std::string& scene_name, int frames) {
  Preview filtered(b.scene, b.filtered, b.width, b.height);
  std::vector<double> pt, filter_app, display;
  StageRow row;
  const auto start = Clock::now();
  for (int i = 0; i < frames; ++i) {
    filtered.add_frame(i + 1 == frames, false);
    const StageTimes& t = filtered.last_times();
    pt.push_back(t.path_tracing);
    if (t.filter > 0) filter_app.push_back(t.filter + t.upload);
    if (t.blend > 0) display.push_back(t.blend + t.tonemap);
    row.range_ms += t.range;
  }
  row.filtered_ms = elapsed_ms(start);
  Preview plain(b.scene, b.plain, b.width, b.height);
  const auto plain_start = Clock::now();
  for (int i = 0; i < frames; ++i) plain.add_frame(i + 1 == frames, false);
  row.plain_ms = elapsed_ms(plain_start);
  row.scene = scene_name;
  row.width = b.width;
  row.height = b.height;
  row.filter_runs = filtered.filter_runs();
  row.pt_ms = median_of(pt);
  row.filter_ms = median_of(filter_app);
  row.display_ms = median_of(display);
  return row;
}

int run_stage_table(SceneOptions scene_options, PreviewOptions preview_options, const CommandLine& cli, int frames,
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
    PreviewOptions po = preview_options;
    BenchSetup b;
    b.scene = load_scene_for(so, po, cli);
    b.width = so.width;
    b.height = so.height;
    b.filtered = po.settings;
    b.plain = b.filtered;
    b.plain.filter_enabled = false;
    const StageRow r = measure_stages(b, builtin.name, frames);
    std::printf("   %-10s %4dx%-4d %8.1f %9.1f %8.1f %8.1f %5d %+8.1f %%\n", r.scene.c_str(), r.width, r.height,
                r.pt_ms, r.filter_ms, r.range_ms, r.display_ms, r.filter_runs, 100.0 * r.overhead());
    csv << r.scene << "," << r.width << "," << r.height << "," << frames << "," << r.pt_ms << "," << r.filter_ms << ","
        << r.range_ms << "," << r.display_ms << "," << r.filter_runs << "," << r.filtered_ms << "," << r.plain_ms
        << "," << 100.0 * r.overhead() << "\n";
    overhead.x.push_back(static_cast<double>(overhead.x.size() + 1));
    overhead.y.push_back(100.0 * r.overhead());
  }
  write_text(out + "/stage_table.csv", csv.str());
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
  bool pathtracer = false, stage_table = false;
  std::string reference_path, out = "bench-out", budgets_text = "8,32,128,256";
  int reference_spp = 2048, frames = 32, max_spp = 1024, timed = 20;
  CommandLine cli("bench", "[options]",
                  "Run time against error on one scene (default cornell, 512x512, default settings):\n"
                  "  1. per-stage times of one scheduled filter application, in ms and in path-tracing frames;\n"
                  "  2. the relative overhead of filtering over --frames frames;\n"
                  "  3. NRMSE to the reference of unfiltered vs filtered images at equal wall time of the whole job\n"
                  "     (the --time machinery), at budgets of --budgets median path-tracing frames;\n"
                  "  4. the spp at which unfiltered path tracing reaches the NRMSE of the filtered image at --frames.\n"
                  "The reference (--reference-spp plain path tracing) is cached in --out. Writes CSV and SVG plots.\n"
                  "--pathtracer instead measures paths/s, rays/s and the raw Embree incoherent-ray rate.");
  add_scene_options(cli, scene_options, /*headless=*/true);
  add_preview_options(cli, preview_options);
  cli.flag("--pathtracer", &pathtracer, "path tracer throughput only");
  cli.flag("--stage-table", &stage_table,
           "per-stage ms and overhead over --frames frames for every built-in scene (no reference)");
  cli.option("--timed-frames", &timed, "timed frames of --pathtracer (after 3 warm-up frames)", 1, 100000);
  cli.option("--reference", &reference_path, "REF.exr", "reference image (default: render and cache one)");
  cli.option("--reference-spp", &reference_spp, "samples of the rendered reference (default 2048)", 1, 1 << 20);
  cli.option("--frames", &frames, "frames of the filtered run (default 32)", 1, 1 << 16);
  cli.option("--budgets", &budgets_text, "LIST", "equal-time budgets in median path-tracing frames (default 8,32,128,256)");
  cli.option("--max-spp", &max_spp, "most unfiltered spp tried to match the filtered NRMSE (default 1024)", 1, 1 << 20);
  cli.option("--out", &out, "DIR", "folder for CSV, plots and the cached reference (default bench-out)");
  if (!cli.parse(args)) return 0;
  if (print_scene_list_if_asked(scene_options)) return 0;
  const std::vector<int> budgets = parse_budgets(budgets_text);
  if (stage_table) {
    std::filesystem::create_directories(out);
    finish_preview_options(preview_options);
    if (!preview_options.settings.filter_enabled) throw UsageError("--filter none: nothing to compare against");
    auto context = create_gl_context(parse_gl_backend(scene_options.gl));
    return run_stage_table(scene_options, preview_options, cli, frames, out);
  }

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
  const PlainRun plain = run_plain(b, std::max(frames, 64), std::max(max_spp, frames),
                                   filtered.nrmse, reference);
  const double plain_frames_ms = plain.wall_ms[frames - 1];
  std::printf("\n2. overhead of filtering over %d frames: %.0f ms filtered vs %.0f ms unfiltered = %+.1f %% (%d filter runs)\n",
              frames, filtered.wall_ms, plain_frames_ms, 100.0 * (filtered.wall_ms / plain_frames_ms - 1.0),
              filtered.filter_runs);

  // 3. Equal time: both runs under the same --time budget of N median path-tracing frames.
  std::printf("\n3. HDR NRMSE to the reference at equal wall time of the whole job (--time = N PT frames):\n");
  std::printf("   budget  time ms | unfiltered spp  used ms  NRMSE   | filtered spp  used ms  NRMSE    ratio\n");
  std::ostringstream eq_csv;
  eq_csv << kEqualTimeCsvHeader;
  PlotSeries filtered_points{"filtered (--time)", {}, {}, true};
  PlotSeries plain_points{"unfiltered (--time)", {}, {}, true};
  for (int budget : budgets) {
    const EqualTimeRow row = run_equal_time(b, budget, pt_ms, reference);
    std::printf("   %6d %8.0f | %14d %8.0f  %6.3f %% | %12d %8.0f  %6.3f %%  %5.2fx\n", budget, row.budget_ms,
                row.plain.spp, row.plain.used_ms, row.plain.metrics.nrmse_percent, row.filtered.spp,
                row.filtered.used_ms, row.filtered.metrics.nrmse_percent,
                row.plain.metrics.nrmse_percent / row.filtered.metrics.nrmse_percent);
    eq_csv << equal_time_csv_row(row);
    filtered_points.x.push_back(row.filtered.used_ms / 1000);
    filtered_points.y.push_back(row.filtered.metrics.nrmse_percent);
    plain_points.x.push_back(row.plain.used_ms / 1000);
    plain_points.y.push_back(row.plain.metrics.nrmse_percent);
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
                 {plain_curve, plain_points, filtered_points, filtered_end});
  std::printf("\nwrote %s/stages.csv, equal_time.csv, convergence.csv, nrmse_vs_time.svg\n", out.c_str());
  return 0;
}

}  // namespace pxf
