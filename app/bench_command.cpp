// pxf bench: run time against error (README "Current figures", docs/measurements.md). Not a
// test: it prints figures and writes CSV and SVG plots into --out.
//   pxf bench                 per-stage times, filtering overhead, equal-time NRMSE, spp to match
//   pxf bench --pathtracer    paths/s, rays/s, ms/frame and the raw Embree ray rate
//   pxf bench --pathtracer --sampler-error | --variance-ratio   the samplers (app/sampler_bench.h)
//   pxf bench --threshold-fidelity   the blend's threshold against the empirical variance (app/fidelity_bench.h)
//   pxf bench --adaptive      adaptive against uniform sampling (app/adaptive_bench.h)
//   pxf bench --guiding-ab    path guiding against none, unfiltered (app/guiding_bench.h)
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "app/adaptive_bench.h"
#include "app/guiding_bench.h"
#include "app/bench_runs.h"
#include "app/motion_bench.h"
#include "app/commands.h"
#include "app/options.h"
#include "app/plot.h"
#include "app/fidelity_bench.h"
#include "app/sampler_bench.h"
#include "app/preview.h"
#include "gl/context.h"
#include "image/metrics.h"
#include "gl/cpu_reference.h"
#include "gl/filter_pass.h"
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

// CSV columns beside the HDR NRMSE ones: "<prefix>display_nrmse_percent,<prefix>flip".
std::string display_csv_header(const std::string& prefix) {
  return prefix + "display_nrmse_percent," + prefix + "flip";
}
std::string display_csv(const RowError& e) {
  std::ostringstream s;
  s << e.display_nrmse << "," << e.flip;
  return s.str();
}

struct BenchSetup {
  Scene scene;
  PreviewSettings filtered, plain;
  int width = 0, height = 0;
  std::string out;
};

// The reference: a high-spp plain path tracing (independent seed), cached in the output folder.
// `layer` "hv": its HV buffer alone (for the variant table; read from layer hv of a given file,
// e.g. the buffers.exr of `pxf render --filter none`), else what plain path tracing shows.
Image obtain_reference(const BenchSetup& b, const std::string& given, int spp, const std::string& scene_name,
                       const std::string& layer = "") {
  if (!given.empty()) return read_exr(given, layer);
  const std::string base = std::filesystem::path(scene_name).stem().string();
  const auto cache_name = [&](const std::string& prefix) {
    return b.out + "/" + prefix + base + "_" + std::to_string(b.width) + "x" + std::to_string(b.height) + "_" +
           std::to_string(spp) + "spp.exr";
  };
  const std::string cache = cache_name(layer == "hv" ? "reference_hv_" : "reference_");
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
  write_exr(cache_name("reference_"), renderer.unfiltered_image());  // both cached: one render serves both
  write_exr(cache_name("reference_hv_"), renderer.hv_image());
  std::printf("reference: wrote %s (%d spp, %.1f s)\n", cache.c_str(), spp, elapsed_ms(start) / 1000);
  return read_exr(cache);
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
std::vector<int> parse_counts(const std::string& option, const std::string& text) {
  std::vector<int> counts;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    char* end = nullptr;
    const long v = std::strtol(item.c_str(), &end, 10);
    if (item.empty() || *end || v < 1 || v > 1 << 16) throw UsageError(option + ": '" + item + "' is not a count");
    counts.push_back(static_cast<int>(v));
  }
  return counts;
}

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
      filter.run(preview.inputs(), preview.range().guide(), params[k], b.filtered.threshold);
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
  write_text(b.out + "/variants.csv", csv.str());
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
  write_text(b.out + "/demodulation.csv", csv.str());
  std::printf("\nwrote %s/demodulation.csv, demod_<unfiltered|off|on>_<budget>.png\n", b.out.c_str());
  return 0;
}

}  // namespace

int run_bench(const Args& args) {
  SceneOptions scene_options;
  PreviewSettings preview_settings;
  bool pathtracer = false, variants = false, stage_table = false, sampler_error = false, variance_ratio = false;
  bool demodulation_ab = false, guiding_ab = false;
  bool threshold_fidelity = false, adaptive = false, motion = false;
  int motion_frames = 60;
  double orbit_degrees = 90;
  double clean_cap_s = 300;
  int variant_spp = 4, variant_rounds = 5;
  std::string extra_taps_text;
  std::string reference_path, out = "bench-out", budgets_text = "8,32,128,256";
  int reference_spp = 2048, frames = 32, max_spp = 1024, timed = 20;
  int seeds = 32, rounds = 7;
  std::string spp_text;
  CommandLine cli("bench", "[options]",
                  "Run time against error on one scene (default cornell, 512x512, default settings):\n"
                  "  1. per-stage times of one scheduled filter application, in ms and in path-tracing frames;\n"
                  "  2. the relative overhead of filtering over --frames frames;\n"
                  "  3. NRMSE to the reference of unfiltered vs filtered images at equal wall time of the whole job\n"
                  "     (the --time machinery), at budgets of --budgets median path-tracing frames, in HDR and on\n"
                  "     display values (both tone-mapped with the reference's key and log-average), with the mean\n"
                  "     LDR-FLIP of the display images;\n"
                  "  4. the spp at which unfiltered path tracing reaches the NRMSE of the filtered image at --frames.\n"
                  "The reference (--reference-spp plain path tracing) is cached in --out. Writes CSV and SVG plots.\n"
                  "--pathtracer instead measures paths/s, rays/s and the raw Embree incoherent-ray rate.\n"
                  "--variants instead tabulates every filter variant on one --variant-spp HV buffer: ms per\n"
                  "application, path-tracing frames, HV-only NRMSE against the reference's HV (layer hv of\n"
                  "--reference, e.g. buffers.exr of `pxf render --filter none`; default: rendered and cached).");
  scene_options.stage_timing = GlTiming::Finish;  // exact per-stage figures
  add_scene_options(cli, scene_options, /*headless=*/true);
  add_preview_options(cli, preview_settings, /*adaptive_option=*/false);
  cli.flag("--pathtracer", &pathtracer, "path tracer throughput only");
  cli.flag("--adaptive", &adaptive,
           "instead of 1-4: adaptive against uniform sampling, both filtered (app/adaptive_bench.h): paths/s at\n"
           "100/50/10 % active pixels, display and HDR NRMSE at equal wall time (--budgets, default 8,32,128,512;\n"
           "--rounds, default 3), starved dark pixels, and the clean share over time up to --clean-cap");
  cli.option("--clean-cap", &clean_cap_s, "seconds of each until-clean run of --adaptive (default 300; 0: none)", 0.0,
             1e6);
  cli.flag("--motion", &motion,
           "a camera orbit of --motion-frames frames over --orbit-degrees, one path per pixel per frame, with the\n"
           "reprojected history and the filter every frame against restart + unfiltered at equal frame time:\n"
           "error, flicker, disocclusions, frame times (references: --reference-spp, default 1024, per frame)");
  cli.option("--motion-frames", &motion_frames, "frames of the --motion orbit (default 60)", 2, 100000);
  cli.option("--orbit-degrees", &orbit_degrees, "the whole --motion orbit in degrees (default 90)", 0.0, 3600.0);
  cli.flag("--variants", &variants, "the filter variant table (time vs HV-only NRMSE)");
  cli.option("--variant-spp", &variant_spp, "spp of the --variants HV buffer (default 4)", 1, 1 << 16);
  cli.option("--variant-rounds", &variant_rounds, "timed rounds of --variants (default 5, after a warm-up)", 1, 1000);
  cli.option("--subsampled-taps", &extra_taps_text, "LIST", "--variants: also the subsampled variant with these tap counts");
  cli.flag("--stage-table", &stage_table,
           "per-stage ms and overhead over --frames frames for every built-in scene (no reference)");
  cli.flag("--sampler-error", &sampler_error,
           "with --pathtracer: unfiltered NRMSE (and LV alone) of sobol vs independent at --spp against a "
           "--reference-spp Sobol reference of another seed, and paths/s of both back to back");
  cli.flag("--variance-ratio", &variance_ratio,
           "with --pathtracer: estimated / empirical Var[L_u] of the pixel mean over --seeds seeds at --spp");
  cli.flag("--threshold-fidelity", &threshold_fidelity,
           "empirical perceived variance of the final image over --seeds seeds at --spp (default 16,64,256) "
           "against --threshold (default both t = 0.001 and 0.01), by blend case (the --filter's; bilateral and bilateral-depth give the "
           "blend the covariance of L_u and L_f); with --adaptive also adaptive sampling at the uniform job's wall time");
  cli.option("--spp", &spp_text, "LIST",
             "spp of --sampler-error (default 8,32,128), --variance-ratio (4,16,64,256) or --threshold-fidelity (16,64,256)");
  cli.option("--seeds", &seeds, "seeds of --variance-ratio and --threshold-fidelity (default 32), --sampler-error (8)", 2, 4096);
  cli.flag("--guiding-ab", &guiding_ab,
           "instead of 1-4: path guiding against none, unfiltered (app/guiding_bench.h): ms per frame at equal spp\n"
           "(--frames), and HDR and display NRMSE at equal wall time of --budgets SECONDS (default 2,8), median of\n"
           "--rounds (default 5) alternating rounds");
  cli.flag("--demodulation-ab", &demodulation_ab,
           "instead of 1-4: albedo demodulation off vs on at equal wall time (--budgets, --rounds rounds, back\n"
           "to back with the unfiltered run); writes demodulation.csv and demod_*.png");
  cli.option("--rounds", &rounds, "rounds of --sampler-error (default 7), --demodulation-ab and --adaptive (default 3)", 1, 1000);
  cli.option("--timed-frames", &timed, "timed frames of --pathtracer (after 3 warm-up frames)", 1, 100000);
  cli.option("--reference", &reference_path, "REF.exr", "reference image (default: render and cache one)");
  cli.option("--reference-spp", &reference_spp, "samples of the rendered reference (default 2048)", 1, 1 << 20);
  cli.option("--frames", &frames, "frames of the filtered run (default 32)", 1, 1 << 16);
  cli.option("--budgets", &budgets_text, "LIST", "equal-time budgets in median path-tracing frames (default 8,32,128,256)");
  cli.option("--max-spp", &max_spp, "most unfiltered spp tried to match the filtered NRMSE (default 1024)", 1, 1 << 20);
  cli.option("--out", &out, "DIR", "folder for CSV, plots and the cached reference (default bench-out)");
  if (!cli.parse(args)) return 0;
  if (print_scene_list_if_asked(scene_options)) return 0;
  set_gl_timing(scene_options.stage_timing);
  const std::vector<int> budgets = parse_counts("--budgets", budgets_text);
  const std::vector<int> extra_taps = parse_counts("--subsampled-taps", extra_taps_text);
  if (stage_table) {
    std::filesystem::create_directories(out);
    if (!preview_settings.filtering()) throw UsageError("--filter none: nothing to compare against");
    auto context = create_gl_context(parse_gl_backend(scene_options.gl));
    return run_stage_table(scene_options, preview_settings, cli, frames, out);
  }

  BenchSetup b;
  b.filtered = preview_settings;
  b.scene = load_scene_for(scene_options, b.filtered, cli);
  b.width = scene_options.width;
  b.height = scene_options.height;
  b.out = out;
  if (!b.filtered.filtering()) throw UsageError("--filter none: nothing to compare against");
  b.plain = b.filtered;
  b.plain.filter.kind = FilterKind::None;
  std::filesystem::create_directories(out);
  if (pathtracer && (sampler_error || variance_ratio)) {
    SamplerBenchSetup sb{b.scene, std::filesystem::path(scene_options.scene).stem().string(), b.plain.trace, b.width,
                         b.height, out};
    if (sampler_error)
      run_sampler_error_bench(sb, cli.given("--reference-spp") ? reference_spp : 2048,
                              parse_counts("--spp", spp_text.empty() ? "8,32,128" : spp_text), rounds,
                              cli.given("--seeds") ? seeds : 8);
    if (variance_ratio) run_variance_ratio_bench(sb, parse_counts("--spp", spp_text.empty() ? "4,16,64,256" : spp_text), seeds);
    return 0;
  }
  if (pathtracer) return run_pathtracer_bench(b, timed);
  if (threshold_fidelity) {
    auto context = create_gl_context(parse_gl_backend(scene_options.gl));
    FidelityBenchSetup fb{b.scene, std::filesystem::path(scene_options.scene).stem().string(), b.filtered,
                          b.width, b.height, out};
    fb.with_adaptive = adaptive;
    const std::vector<float> thresholds =
        cli.given("--threshold") ? std::vector<float>{preview_settings.threshold} : std::vector<float>{0.001f, 0.01f};
    run_threshold_fidelity_bench(fb, parse_counts("--spp", spp_text.empty() ? "16,64,256" : spp_text), thresholds,
                                 seeds);
    return 0;
  }

  auto context = create_gl_context(parse_gl_backend(scene_options.gl));
  if (motion) {
    MotionBenchSetup mb{b.scene, scene_options.scene, b.filtered, b.width, b.height, out};
    mb.frames = motion_frames;
    mb.orbit_degrees = static_cast<float>(orbit_degrees);
    mb.reference_spp = cli.given("--reference-spp") ? reference_spp : 1024;
    run_motion_bench(mb);
    return 0;
  }
  std::printf("bench: %s %dx%d, t=%g, filter %s, sigma_s=%g sigma_c=%g sigma_d=%g, GL %s (%s)\n",
              scene_options.scene.c_str(), b.width, b.height, b.filtered.threshold,
              filter_kind_name(b.filtered.filter.kind), b.filtered.filter.sigma_s, b.filtered.filter.sigma_c,
              b.filtered.filter.sigma_d, context->backend_name(), context->gl_renderer().c_str());
  if (variants)
    return run_variant_bench(b, obtain_reference(b, reference_path, reference_spp, scene_options.scene, "hv"),
                             variant_spp, variant_rounds, extra_taps);
  const Image reference = obtain_reference(b, reference_path, reference_spp, scene_options.scene);
  if (reference.width != b.width || reference.height != b.height) throw Error("reference size differs from --size");

  if (guiding_ab) {
    GuidingBenchPlan plan;
    plan.budgets_s = parse_counts("--budgets", cli.given("--budgets") ? budgets_text : "2,8");
    plan.rounds = cli.given("--rounds") ? rounds : 5;
    plan.cost_frames = frames;
    run_guiding_bench({b.scene, b.plain.trace, b.width, b.height, out, reference}, plan);
    return 0;
  }
  if (adaptive) {
    AdaptiveBenchPlan plan;
    plan.budgets = parse_counts("--budgets", cli.given("--budgets") ? budgets_text : "8,32,128,512");
    plan.rounds = cli.given("--rounds") ? rounds : 3;
    plan.clean_cap_s = clean_cap_s;
    run_adaptive_bench({b.scene, std::filesystem::path(scene_options.scene).stem().string(), b.filtered, b.width,
                        b.height, out, reference},
                       plan);
    return 0;
  }
  if (demodulation_ab) {
    // The budgets' unit: the median path-tracing frame of a short unfiltered warm-up.
    Preview warm(b.scene, b.plain, b.width, b.height);
    std::vector<double> frame_ms;
    for (int i = 0; i < 8; ++i) {
      warm.add_frame(i == 7, i == 7);
      frame_ms.push_back(warm.last_times().path_tracing);
    }
    return run_demodulation_ab(b, reference, median_of(frame_ms), budgets, cli.given("--rounds") ? rounds : 3);
  }

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
  write_text(out + "/stages.csv", stages_csv.str());
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
  write_text(out + "/equal_time.csv", eq_csv.str());

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
  write_text(out + "/convergence.csv", conv_csv.str());
  PlotSeries filtered_end{"filtered " + std::to_string(frames) + " spp", {filtered.wall_ms / 1000}, {filtered.nrmse}, true};
  write_svg_plot(out + "/nrmse_vs_time.svg",
                 {"NRMSE vs wall time: " + scene_options.scene, "wall time (s)", "NRMSE (%)", true, true},
                 {plain_curve, plain_points, filtered_points, filtered_end});
  std::printf("\nwrote %s/stages.csv, equal_time.csv, convergence.csv, nrmse_vs_time.svg\n", out.c_str());
  return 0;
}

}  // namespace pxf
