// pxf render: headless progressive capture with pixel filtering.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <unistd.h>

#include "app/camera_path_render.h"
#include "app/checkpoint.h"
#include "app/commands.h"
#include "app/first_frame.h"
#include "app/options.h"
#include "app/output_set.h"
#include "preview/preview.h"
#include "app/render_output.h"
#include "app/stop_signal.h"
#include "core/timing.h"
#include "gl/context.h"

namespace pxf {

namespace {

// "[#######.....]  12/64 spp  1.2 s elapsed  ETA 5.1 s" on stderr, at most ~10 times a second.
class ProgressBar {
 public:
  explicit ProgressBar(int total) : total_(total), start_(std::chrono::steady_clock::now()), tty_(isatty(2)) {}
  void update(int done, bool force = false) {
    const auto now = std::chrono::steady_clock::now();
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    if (!force && elapsed - last_print_ < (tty_ ? 0.1 : 5.0)) return;
    last_print_ = elapsed;
    const int width = 30, filled = total_ ? width * done / total_ : width;
    const double eta = done ? elapsed * (total_ - done) / done : 0.0;
    std::fprintf(stderr, "%s[%s%s] %d/%d spp  %.1f s elapsed  ETA %.1f s%s", tty_ ? "\r" : "",
                 std::string(filled, '#').c_str(), std::string(width - filled, '.').c_str(), done, total_, elapsed,
                 eta, tty_ ? "   " : "\n");
    std::fflush(stderr);
  }
  void finish() {
    if (tty_) std::fputc('\n', stderr);
  }

 private:
  int total_;
  std::chrono::steady_clock::time_point start_;
  bool tty_;
  double last_print_ = -1e9;
};

// render --camera-path: the frame sequence (app/camera_path_render.h).
int render_camera_path(const std::string& camera_path, PathRenderOptions path_options, const std::string& out,
                       bool quiet, SceneOptions& scene_options, PreviewSettings& preview_settings,
                       const CommandLine& cli) {
  path_options.out = out;
  path_options.quiet = quiet;
  Scene scene = load_scene_for(scene_options, preview_settings, cli);
  check_output_folder(out);  // before the path's cameras are made and traced
  const CameraPath path = camera_path_for(camera_path, scene);
  set_gl_timing(scene_options.stage_timing);
  auto context = create_gl_context(parse_gl_backend(scene_options.gl));
  return run_camera_path_render(scene, scene_options.scene, preview_settings, scene_options.width,
                                scene_options.height, path, path_options);
}

// The frames of a render, from the first one the preview lacks (> 0 after --resume) until `total`,
// the budget, a clean image (report->until_clean) or a stop signal; the clean checks go to *report.
void trace_render_frames(Preview& preview, Checkpointer& checkpointer, ProgressBar& progress, int total,
                         double budget_ms, BenchClock::time_point start, bool quiet, RenderReport* report) {
  const int first = preview.samples();
  GrowingSchedule checks = clean_checks(first);
  for (int i = first; i < total && !stop_signal(); ++i) {
    // The first frame always traces; the next ones only while they and the finish fit the budget.
    if (i > first && !next_frame_fits(preview.predict_next_frame(budget_ms, elapsed_ms(start)))) break;
    // With a budget the first frame is displayed: that measures the finish's blend and tone map.
    // Clean is the blend's finding on a fresh filter run: a check frame is run like a last frame
    // (filter and blend; app/adaptive.h, clean_checks).
    const bool check_clean = report->until_clean && checks.due(preview.samples() + 1);
    preview.add_frame(/*last_frame=*/check_clean, /*display=*/check_clean || (i == first && budget_ms > 0));
    if (check_clean) {
      report->case2_share_over_time.push_back({elapsed_ms(start), double(preview.samples()), preview.case2_share()});
      checks.done(preview.samples());
    }
    checkpointer.maybe_write(preview);
    if (!quiet) progress.update(i + 1, i + 1 == total);
    if (check_clean && preview.clean()) {
      report->clean_ms = elapsed_ms(start);
      if (preview.case2_share() < 1.0)
        std::printf("until-clean: clean at %d spp with no filter run: HV carries %.3g %% of the energy, below the "
                    "%g %% the filter runs from, so every pixel is unfiltered and unbiased\n",
                    preview.samples(), 100.0 * hv_energy_share(preview.renderer().accumulation()), 100.0 * kMinHvShare);
      break;
    }
  }
}

// What a finished render prints: its times, the budget, the error against a reference and the files.
void print_render_summary(const SceneOptions& scene_options, const Preview& preview, const RenderReport& report,
                          const std::string& out, const Checkpointer& checkpointer) {
  const StageTimes& t = preview.total_times();
  std::printf("%s: %dx%d, %d spp%s, %.2f s (path tracing %.0f ms, upload %.0f, range %.0f, filter %.0f in %d runs, "
              "blend %.0f, tone map %.0f)\n",
              scene_options.scene.c_str(), preview.width(), preview.height(), preview.samples(),
              report.interrupted ? " (interrupted)" : "", report.wall_ms / 1000.0, t.path_tracing, t.upload, t.range,
              t.filter, preview.filter_runs(), t.blend, t.tonemap);
  std::printf("outside path tracing: %.1f %% of the job (filter + range %.1f %% of the tracing)\n",
              100.0 * share_outside_tracing(t, report.used_ms), 100.0 * pass_share_of_tracing(t));
  if (report.budget_ms > 0)
    std::printf("time budget %.2f s: used %.2f s until the finish\n", report.budget_ms / 1000.0,
                report.used_ms / 1000.0);
  if (report.final_vs_reference)
    std::printf("NRMSE vs reference: final %.3f %%, unfiltered %.3f %%\n", report.final_vs_reference->nrmse_percent,
                report.unfiltered_vs_reference->nrmse_percent);
  std::printf("wrote %s/final.png, %s/final.exr, %s/buffers.exr, %s/stats.json\n", out.c_str(), out.c_str(),
              out.c_str(), out.c_str());
  if (checkpointer.written())
    std::printf("wrote %s (state writes %.0f ms in all)\n", state_path(out).c_str(), checkpointer.write_ms());
}

}  // namespace

int run_render(const Args& args) {
  SceneOptions scene_options;
  PreviewSettings preview_settings;
  int spp = 64;
  double time_s = 0;
  std::string out = "out", reference;
  bool quiet = false;
  CommandLine cli("render", "[options]",
                  "Renders a scene progressively with pixel filtering, headless, and writes DIR/final.png\n"
                  "(tone-mapped), DIR/final.exr, DIR/buffers.exr (final, lv, hv, hv_filtered, var_u, var_f,\n"
                  "blend, case, range_color, depth, samples) and DIR/stats.json, replaced as one set. Ctrl-C,\n"
                  "SIGTERM or SIGHUP finishes the current frame and writes everything (exit 128 + the signal).\n"
                  "A reference: --filter none --spp 4096.");
  add_scene_options(cli, scene_options, /*headless=*/true);
  cli.option("--spp", &spp, "samples (path-traced frames) per pixel (default 64; unbounded with --time alone)", 1,
             static_cast<int>(kMaxRenderFrames));
  cli.option("--time", &time_s,
             "wall-clock budget in seconds of the whole job (load, trace, passes, finish); with --spp: first wins",
             0.001, 1e7);
  add_preview_options(cli, preview_settings);
  cli.option("--reference", &reference, "REF.exr", "report NRMSE of the final and the unfiltered image against it");
  cli.option("--out", &out, "DIR", "output folder (default out)");
  cli.flag("--quiet", &quiet, "no progress bar");
  bool until_clean = false;
  cli.flag("--until-clean", &until_clean,
           "stop once every pixel is case 2 (the unbiased image at threshold t), checked by a filter run and a blend "
           "at 16 frames and each time the frames grew by a quarter; or earlier at --spp (unbounded without it), "
           "--time or Ctrl-C");
  CheckpointOptions checkpoint_options;
  add_checkpoint_options(cli, checkpoint_options);
  std::string camera_path;
  PathRenderOptions path_options;
  cli.option("--camera-path", &camera_path, "FILE.json|turntable:N",
             "render a numbered frame sequence DIR/frame-NNNN.png along a camera path (docs/explorer.md), "
             "the history reprojected from frame to frame");
  cli.option("--spp-per-frame", &path_options.spp_per_frame, "with --camera-path: samples per frame (default 1)", 1,
             static_cast<int>(kMaxRenderFrames));
  cli.option("--time-per-frame", &path_options.time_per_frame_s,
             "with --camera-path: seconds per frame instead of --spp-per-frame", 0.001, 1e7);
  if (!cli.parse(args)) return 0;
  if (print_scene_list_if_asked(scene_options)) return 0;
  if (camera_path.empty()) {
    for (const char* flag : {"--spp-per-frame", "--time-per-frame"})
      if (cli.given(flag)) throw UsageError(std::string(flag) + " needs --camera-path");
  } else {
    for (const char* flag : {"--spp", "--time", "--until-clean", "--reference"})
      if (cli.given(flag)) throw UsageError(std::string(flag) + " does not go with --camera-path (use --spp-per-frame or --time-per-frame)");
    if (cli.given("--spp-per-frame") && cli.given("--time-per-frame"))
      throw UsageError("--spp-per-frame and --time-per-frame exclude each other");
    if (uses_state(checkpoint_options)) throw UsageError("checkpoints do not go with --camera-path");
    return render_camera_path(camera_path, path_options, out, quiet, scene_options, preview_settings, cli);
  }
  const double budget_ms = time_s * 1000.0;
  if ((budget_ms > 0 || until_clean) && !cli.given("--spp")) {
    spp = static_cast<int>(kMaxRenderFrames);
    quiet = true;  // no total to show progress against
  }
  // Without a filter the blend has no case 2 to count.
  if (until_clean && !preview_settings.filtering()) throw UsageError("--until-clean needs a filter (not --filter none)");
  // Case 2 is a variance of at most t: at t = 0 only a noiseless pixel gets there, so the render
  // could never end.
  if (until_clean && !(preview_settings.threshold > 0.0f))
    throw UsageError("--until-clean needs --threshold above 0: at 0 no noisy pixel can become clean");
  if (until_clean) preview_settings.adaptive_params.goal = AdaptiveGoal::Clean;  // app/adaptive.h

  const FrameRange frames = render_frame_range(checkpoint_options, spp);  // a bad range before any load

  const auto start = BenchClock::now();
  Scene scene = load_scene_for(scene_options, preview_settings, cli);
  const double load_ms = elapsed_ms(start);
  if (!reference.empty()) check_reference(reference, scene_options.width, scene_options.height);  // before tracing
  check_output_folder(out);  // a folder that cannot take the outputs is refused before the tracing
  set_gl_timing(scene_options.stage_timing);
  auto context = create_gl_context(parse_gl_backend(scene_options.gl));
  // The first frame traces whatever the budget: refused up front when even it cannot fit.
  check_first_frame_fits(scene, preview_settings, scene_options.width, scene_options.height, budget_ms,
                         elapsed_ms(start));
  Preview preview(scene, preview_settings, scene_options.width, scene_options.height);
  Checkpointer checkpointer(checkpoint_options, out, render_sample_settings(scene_options, preview_settings),
                            frames);
  checkpointer.start(preview);

  const StopSignalHandlers stop_handlers;  // kept through the writes: a stop then still gives 128 + signal
  const int total = static_cast<int>(frames.count());
  ProgressBar progress(total);
  RenderReport report;
  report.until_clean = until_clean;
  trace_render_frames(preview, checkpointer, progress, total, budget_ms, start, quiet, &report);
  preview.finish();
  const double used_ms = elapsed_ms(start);
  const std::string state_error = checkpointer.write_final(preview);  // reported after the outputs
  if (!quiet) progress.finish();

  report.scene = &scene_options;
  report.interrupted = stop_signal() != 0;
  report.gl_backend = context->backend_name();
  report.gl_renderer = context->gl_renderer();
  report.reference_path = reference;
  report.budget_ms = budget_ms;
  report.used_ms = used_ms;
  report.wall_ms = elapsed_ms(start);
  report.load_ms = load_ms;
  try {
    write_render_outputs(out, preview, report);
  } catch (const Error&) {
    // Both failed (a full disk): the state's line first, then the outputs' (main prints it).
    if (!state_error.empty()) std::fprintf(stderr, "pxf render: %s\n", state_error.c_str());
    throw;
  }

  print_render_summary(scene_options, preview, report, out, checkpointer);
  if (!state_error.empty()) {
    std::fprintf(stderr, "pxf render: %s\n", state_error.c_str());
    return 1;
  }
  return stop_signal() ? 128 + stop_signal() : 0;
}

}  // namespace pxf
