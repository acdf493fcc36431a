// What `pxf render` (and the explorer's capture) writes: final.png, final.exr, buffers.exr and
// stats.json in an output folder, replaced as one unit (app/output_set.h): after any kill the
// folder shows the whole previous set or the whole new one.
#pragma once
#include <array>
#include <optional>
#include <string>

#include "preview/preview.h"
#include "app/options.h"
#include "image/image.h"

namespace pxf {

struct RenderReport {
  const SceneOptions* scene = nullptr;
  double wall_ms = 0;
  double budget_ms = 0;  // --time (0 = none)
  double used_ms = 0;    // from the start until the finish (files not included)
  double load_ms = 0;  // the scene and environment load (load_scene_for)
  bool interrupted = false;
  std::string gl_backend, gl_renderer;
  std::string reference_path;  // optional: NRMSE of the final and the unfiltered image against it
  // --until-clean: when every pixel became case 2 (ms from the start, < 0 = not reached), and the
  // share of case-2 pixels at each filter run: {ms from the start, spp, share}.
  bool until_clean = false;
  double clean_ms = -1;
  std::vector<std::array<double, 3>> case2_share_over_time;
  std::optional<ImageMetrics> final_vs_reference, unfiltered_vs_reference;  // filled by the writer
};

// The unfiltered image L_lv + L_u (what plain path tracing shows), from the preview's buffers.
Image unfiltered_image(const std::vector<Layer>& buffers);

// Reads the --reference EXR and checks that it matches the render size, so that a bad reference is
// reported before the render rather than after it; throws pxf::Error naming the file.
void check_reference(const std::string& path, int width, int height);

// Writes DIR/final.png, DIR/final.exr, DIR/buffers.exr, DIR/stats.json; creates DIR.
void write_render_outputs(const std::string& dir, Preview& preview, RenderReport& report);

}  // namespace pxf
