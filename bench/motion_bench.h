// pxf bench motion: a camera orbit or a camera path, one path per pixel per frame, with the reprojected
// history and the filter every frame, against today's explorer behaviour during motion (restart
// plus unfiltered) at equal frame time. Not a test: prints a table and writes motion.csv and frames
// into --out.
//   error:   display NRMSE of each frame against a reference of that view (--reference-spp plain
//            path tracing of another seed), tone-mapped with the reference's key and log-average; median
//   flicker: NRMSE of the displayed frame-to-frame difference against the references' own
//            difference (both in display values), and the references' own change; medians
//   disocclusions: the display RMSE over the pixels the history rejected as disoccluded, of both
//   speed:   the longest and the median frame time, and the history passes' share
#pragma once
#include <string>

#include "preview/preview.h"

namespace pxf {

struct MotionBenchSetup {
  const Scene& scene;
  std::string scene_name;
  PreviewSettings settings;  // the history run's (filter, threshold, ...)
  int width = 0, height = 0;
  std::string out;
  int frames = 60;              // of the orbit
  float orbit_degrees = 90.0f;  // the whole orbit, around the explorer's orbit target
  // A camera path (app/camera_path.h: a JSON file or turntable:N) instead of the orbit: its frames.
  std::string camera_path{};
  int reference_spp = 1024;
  // A second reference per frame (another seed) for the error less the references' own noise.
  bool second_reference = true;
};

void run_motion_bench(const MotionBenchSetup& b);

}  // namespace pxf
