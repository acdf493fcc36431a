// What several `pxf bench` tables share: the error figures of one row and one job under a wall-time
// budget (the render command's --time machinery).
#pragma once
#include "image/image.h"
#include "preview/preview.h"

namespace pxf {

// The error figures of one bench row, one call per row: HDR NRMSE, and on the images tone-mapped
// with the reference's key and log-average, display NRMSE and mean LDR-FLIP (image/metrics.h).
struct RowError {
  double hdr_nrmse = 0, display_nrmse = 0, flip = 0;
};
RowError row_error(const Image& test, const Image& reference);

// One job under `--time`: frames while the next one, its due passes and the finish fit the budget,
// then the finish.
struct TimedRun {
  int spp = 0;           // frames
  double paths_per_pixel = 0;  // mean paths per pixel (fewer than frames under adaptive sampling)
  double used_ms = 0;
  int filter_runs = 0;
  StageTimes times;
  RowError error;    // of the final image: HDR NRMSE, display NRMSE, FLIP
  Image image;       // the final linear image
  Image unfiltered;  // L_lv + L_u of the same samples
};
TimedRun run_timed(const Scene& scene, const PreviewSettings& settings, int width, int height, double budget_ms,
                   const Image& reference);

}  // namespace pxf
