#include "app/first_frame.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "core/error.h"

namespace pxf {

void probe_size(int width, int height, int& probe_width, int& probe_height) {
  const double scale = std::sqrt(kProbePixels / (double(width) * height));
  probe_width = std::clamp(static_cast<int>(std::lround(width * scale)), 1, width);
  probe_height = std::clamp(static_cast<int>(std::lround(height * scale)), 1, height);
}

double scaled_first_frame_ms(double probe_ms, double probe_pixels, double pixels) {
  return probe_pixels > 0 ? probe_ms * pixels / probe_pixels : 0.0;
}

std::string first_frame_refusal(double predicted_ms, double elapsed_ms, double budget_ms, int width, int height) {
  if (elapsed_ms + predicted_ms <= budget_ms) return "";
  char line[320];
  std::snprintf(line, sizeof line,
                "--time %.3g s cannot hold one frame at %dx%d: it would take about %.1f s (a probe frame, scaled to the "
                "pixels) with %.1f s already spent; raise --time or lower --size",
                budget_ms / 1000.0, width, height, predicted_ms / 1000.0, elapsed_ms / 1000.0);
  return line;
}

void check_first_frame_fits(const Scene& scene, const PreviewSettings& settings, int width, int height,
                            double budget_ms, double elapsed_ms) {
  const double pixels = double(width) * height;
  if (budget_ms <= 0 || pixels <= kProbePixels) return;
  int probe_width = 0, probe_height = 0;
  probe_size(width, height, probe_width, probe_height);
  const auto start = std::chrono::steady_clock::now();
  // What the render's first frame does under a budget: trace, the passes due, display, finish.
  // Timed on the probe's second first frame: the first compiles the passes' shaders (llvmpipe
  // compiles on first use), a fixed cost that scaled to the pixels would overstate the frame severalfold.
  Preview probe(scene, settings, probe_width, probe_height);
  auto first_frame = [&probe] {
    probe.add_frame(/*last_frame=*/false, /*display=*/true);
    probe.finish();
  };
  first_frame();
  probe.reset();
  const auto timed = std::chrono::steady_clock::now();
  first_frame();
  const auto end = std::chrono::steady_clock::now();
  const double frame_ms = std::chrono::duration<double, std::milli>(end - timed).count();
  const double probe_ms = std::chrono::duration<double, std::milli>(end - start).count();
  const double predicted = scaled_first_frame_ms(frame_ms, double(probe_width) * probe_height, pixels);
  const std::string refusal = first_frame_refusal(predicted, elapsed_ms + probe_ms, budget_ms, width, height);
  if (!refusal.empty()) throw Error(refusal);
}

}  // namespace pxf
