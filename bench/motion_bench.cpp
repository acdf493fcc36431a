#include "bench/motion_bench.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "app/camera_path.h"
#include "scene/camera_controls.h"
#include "core/timing.h"
#include "image/metrics.h"

namespace pxf {

namespace {

constexpr float kOrbitRadiansPerPixel = 0.005f;  // CameraController::orbit

std::vector<Camera> bench_cameras(const MotionBenchSetup& b) {
  std::vector<Camera> cameras;
  if (!b.camera_path.empty()) {
    const CameraPath path = camera_path_for(b.camera_path, b.scene);
    for (int f = 0; f < path.frame_count(); ++f) cameras.push_back(camera_on_path(path, f, b.scene.camera));
    return cameras;
  }
  CameraController control(b.scene.camera, scene_bounds(b.scene));
  const float step_px = glm::radians(b.orbit_degrees / static_cast<float>(b.frames)) / kOrbitRadiansPerPixel;
  for (int f = 0; f < b.frames; ++f) {
    cameras.push_back(control.camera());
    control.orbit(step_px, 0.0f);
  }
  return cameras;
}

std::string frame_file(const std::string& dir, const std::string& prefix, int frame, const char* ext) {
  char name[64];
  std::snprintf(name, sizeof name, "%s_%04d.%s", prefix.c_str(), frame, ext);
  return dir + "/" + name;
}

// Plain path tracing of each view with another seed (`which` 1 or 2: two independent references,
// the second for the reference-noise correction), cached in --out under a name that says which views.
std::vector<Image> references(const MotionBenchSetup& b, const std::vector<Camera>& cameras, int which) {
  const std::string views = b.camera_path.empty()
                                ? std::to_string(b.frames) + "f_" + std::to_string(static_cast<int>(b.orbit_degrees)) + "deg_"
                                : "path-" + std::filesystem::path(b.camera_path).stem().string() + "_" +
                                      std::to_string(cameras.size()) + "f_";
  const std::string dir = b.out + "/motion_reference" + (which == 1 ? std::string() : std::to_string(which)) + "_" +
                          std::filesystem::path(b.scene_name).stem().string() + "_" + std::to_string(b.width) + "x" +
                          std::to_string(b.height) + "_" + views + std::to_string(b.reference_spp) + "spp";
  std::filesystem::create_directories(dir);
  std::vector<Image> refs;
  TraceParams params = b.settings.trace;
  params.seed = b.settings.trace.seed + 7919 * which;  // independent of the runs being judged
  const auto start = BenchClock::now();
  for (size_t f = 0; f < cameras.size(); ++f) {
    const std::string file = frame_file(dir, "reference", static_cast<int>(f), "exr");
    if (!std::filesystem::exists(file)) {
      ProgressiveRenderer renderer(b.scene, params, b.width, b.height);
      renderer.set_camera(cameras[f]);
      for (int i = 0; i < b.reference_spp; ++i) renderer.add_frame();
      write_exr(file, renderer.unfiltered_image());
      std::fprintf(stderr, "reference %zu/%zu: %d spp, %.0f s in all\n", f + 1, cameras.size(), b.reference_spp,
                   elapsed_ms(start) / 1000);
    }
    refs.push_back(read_exr(file));
  }
  return refs;
}

struct MotionRun {
  std::vector<Image> finals;     // linear "R,G,B"
  std::vector<double> ms;        // wall time of each frame: camera change, tracing, passes, display
  std::vector<int> spp;          // traced frames of each view
  std::vector<Image> disoccluded;  // history run: "Y" 1 where the history was rejected as disoccluded
  std::vector<Image> outcome;      // history run: the reprojection's outcome as colors (history_outcome_colors)
  double history_ms = 0;         // the history passes in all
};

MotionRun run_with_history(const MotionBenchSetup& b, const std::vector<Camera>& cameras) {
  PreviewSettings settings = b.settings;
  settings.motion_history = true;
  Preview preview(b.scene, settings, b.width, b.height);
  MotionRun run;
  for (const Camera& camera : cameras) {
    const auto start = BenchClock::now();
    preview.set_camera(camera);
    preview.add_frame(false, true);
    run.ms.push_back(elapsed_ms(start));
    run.spp.push_back(preview.samples());
    run.finals.push_back(preview.final_image());
    Image mask = Image::gray(b.width, b.height);
    Image colors = Image::rgb(b.width, b.height);
    if (preview.history() && preview.history()->reprojected()) {
      const Image outcome = preview.history()->outcome_image();
      colors = history_outcome_colors(outcome);
      for (size_t i = 0; i < mask.pixels.size(); ++i)
        mask.pixels[i] = outcome.pixels[i] == shared::kHistoryDisoccluded ? 1.0f : 0.0f;
    }
    run.disoccluded.push_back(std::move(mask));
    run.outcome.push_back(std::move(colors));
  }
  run.history_ms = preview.history() ? preview.history()->total_ms() : 0.0;
  return run;
}

// Today's explorer while the camera moves: each move restarts, no filter, as many paths per pixel
// as fit in `frame_ms` (at least one).
MotionRun run_restarting(const MotionBenchSetup& b, const std::vector<Camera>& cameras, double frame_ms) {
  PreviewSettings settings = b.settings;
  settings.motion_history = false;
  settings.filter.kind = FilterKind::None;
  Preview preview(b.scene, settings, b.width, b.height);
  MotionRun run;
  for (const Camera& camera : cameras) {
    const auto start = BenchClock::now();
    preview.set_camera(camera);
    double one_frame_ms = 0;
    do {
      const auto frame_start = BenchClock::now();
      preview.add_frame(false, false);
      one_frame_ms = std::max(one_frame_ms, elapsed_ms(frame_start));
    } while (elapsed_ms(start) + one_frame_ms <= frame_ms);
    preview.finish();
    run.ms.push_back(elapsed_ms(start));
    run.spp.push_back(preview.samples());
    run.finals.push_back(preview.final_image());
  }
  return run;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

double mean_of(const Image& image) {
  double sum = 0;
  for (float v : image.pixels) sum += v;
  return image.pixels.empty() ? 0.0 : sum / image.pixels.size();
}

// RMS of a - b over every channel, in % of `scale`.
double rms_difference_percent(const Image& a, const Image& b, double scale) {
  double sum = 0;
  for (size_t i = 0; i < a.pixels.size(); ++i) sum += double(a.pixels[i] - b.pixels[i]) * (a.pixels[i] - b.pixels[i]);
  return scale > 0 ? 100.0 * std::sqrt(sum / a.pixels.size()) / scale : 0.0;
}

struct RunFigures {
  std::vector<double> error, change;  // per frame (change from frame 1 on)
  std::vector<Image> display;
  double disoccluded_sq = 0;  // squared display error summed over the disoccluded pixels' channels
};

RunFigures figures(const MotionRun& run, const std::vector<Image>& refs, const std::vector<Image>& ref_display,
                   const std::vector<Image>& disoccluded) {
  RunFigures r;
  for (size_t f = 0; f < refs.size(); ++f) {
    r.error.push_back(compare_display(run.finals[f], refs[f]).display_nrmse_percent);
    r.display.push_back(tonemap_like_reference(run.finals[f], refs[f]).test);
    // Each frame at its own reference's exposure, as the references' own change is measured.
    if (f > 0) r.change.push_back(rms_difference_percent(r.display[f], r.display[f - 1], mean_of(ref_display[f])));
    const Image& mask = disoccluded[f];
    for (size_t p = 0; p < mask.pixels.size(); ++p)
      if (mask.pixels[p] > 0)
        for (int c = 0; c < 3; ++c) {
          const double d = r.display[f].pixels[3 * p + c] - ref_display[f].pixels[3 * p + c];
          r.disoccluded_sq += d * d;
        }
  }
  return r;
}

}  // namespace

void run_motion_bench(const MotionBenchSetup& b) {
  std::filesystem::create_directories(b.out);
  const std::vector<Camera> cameras = bench_cameras(b);
  const std::vector<Image> refs = references(b, cameras, 1);
  std::vector<double> reference_pair;  // display NRMSE of the second reference against the first
  if (b.second_reference) {
    const std::vector<Image> second = references(b, cameras, 2);
    for (size_t f = 0; f < refs.size(); ++f)
      reference_pair.push_back(compare_display(second[f], refs[f]).display_nrmse_percent);
  }
  std::vector<Image> ref_display;
  std::vector<double> ref_change;
  for (size_t f = 0; f < refs.size(); ++f) {
    ref_display.push_back(tonemap_like_reference(refs[f], refs[f]).reference);
    if (f > 0)
      ref_change.push_back(rms_difference_percent(ref_display[f], ref_display[f - 1], mean_of(ref_display[f])));
  }

  const MotionRun history = run_with_history(b, cameras);
  // Frames 0 and 1 compile the shaders of the passes: left out of the frame time.
  const std::vector<double> timed(history.ms.begin() + std::min<size_t>(2, history.ms.size()), history.ms.end());
  const double history_frame_ms = median(timed);
  const MotionRun today = run_restarting(b, cameras, history_frame_ms);

  const RunFigures h = figures(history, refs, ref_display, history.disoccluded);
  const RunFigures t = figures(today, refs, ref_display, history.disoccluded);
  double disoccluded_values = 0;
  for (const Image& m : history.disoccluded) disoccluded_values += 3.0 * std::count(m.pixels.begin(), m.pixels.end(), 1.0f);

  std::ofstream csv(b.out + "/motion.csv");
  csv << "frame,ms_history,ms_today,spp_today,error_history,error_today,error_reference_pair,change_history,"
         "change_today,change_reference\n";
  for (size_t f = 0; f < cameras.size(); ++f) {
    csv << f << "," << history.ms[f] << "," << today.ms[f] << "," << today.spp[f] << "," << h.error[f] << ","
        << t.error[f] << ",";
    if (b.second_reference) csv << reference_pair[f];
    if (f > 0) csv << "," << h.change[f - 1] << "," << t.change[f - 1] << "," << ref_change[f - 1];
    csv << "\n";
    write_png(frame_file(b.out, "motion_history", static_cast<int>(f), "png"), h.display[f]);
    write_png(frame_file(b.out, "motion_today", static_cast<int>(f), "png"), t.display[f]);
    write_png(frame_file(b.out, "motion_reference", static_cast<int>(f), "png"), ref_display[f]);
    write_png(frame_file(b.out, "motion_outcome", static_cast<int>(f), "png"), history.outcome[f]);
  }

  std::vector<double> today_spp(today.spp.begin(), today.spp.end());
  if (b.camera_path.empty())
    std::printf("motion: %s %dx%d, %d frames over %.0f degrees of orbit, references %d spp (another seed)\n",
                b.scene_name.c_str(), b.width, b.height, b.frames, b.orbit_degrees, b.reference_spp);
  else
    std::printf("motion: %s %dx%d, camera path %s (%zu frames), references %d spp (another seed)\n",
                b.scene_name.c_str(), b.width, b.height, b.camera_path.c_str(), cameras.size(), b.reference_spp);
  std::printf("  frame time: history + filter median %.1f ms, longest %.1f ms (frames 2+); history passes %.2f ms a frame\n",
              history_frame_ms, timed.empty() ? 0.0 : *std::max_element(timed.begin(), timed.end()),
              history.history_ms / cameras.size());
  std::printf("  today (restart, unfiltered) at equal frame time: median %.1f ms, median %.0f spp a frame\n",
              median(today.ms), median(today_spp));
  const double eh = median(h.error), et = median(t.error);
  std::printf("  error (display NRMSE, median over frames): history %.2f %%, today %.2f %%, ratio %.2f\n", eh, et,
              et > 0 ? eh / et : 0.0);
  std::vector<double> hc, tc;
  for (size_t f = 0; b.second_reference && f < refs.size(); ++f) {
    hc.push_back(correct_for_reference_noise(h.error[f], reference_pair[f]).corrected_percent);
    tc.push_back(correct_for_reference_noise(t.error[f], reference_pair[f]).corrected_percent);
  }
  const double ehc = median(hc), etc_ = median(tc);
  if (b.second_reference)
    std::printf("  error less the references' own noise (%.2f %% between the two references, median): history %.2f %%, "
              "today %.2f %%, ratio %.2f\n",
              median(reference_pair), ehc, etc_, etc_ > 0 ? ehc / etc_ : 0.0);
  const double ch = median(h.change), ct = median(t.change), cr = median(ref_change);
  std::printf("  flicker (frame-to-frame change, display NRMSE, median): history %.2f %%, today %.2f %%, references "
              "%.2f %%; history / references %.2f, today / references %.2f\n",
              ch, ct, cr, cr > 0 ? ch / cr : 0.0, cr > 0 ? ct / cr : 0.0);
  if (disoccluded_values > 0)
    std::printf("  disoccluded pixels (%.0f pixel-frames): display RMSE history %.4f, today %.4f\n",
                disoccluded_values / 3.0, std::sqrt(h.disoccluded_sq / disoccluded_values),
                std::sqrt(t.disoccluded_sq / disoccluded_values));
  std::printf("  wrote %s/motion.csv and motion_{history,today,reference,outcome}_NNNN.png\n", b.out.c_str());
}

}  // namespace pxf
