// `pxf render --camera-path`: a numbered frame sequence along a camera path (app/camera_path.h)
// through the preview core, the reprojected history carrying each frame into the next as in the
// explorer (docs/method.md 4.1).
#pragma once
#include <string>

#include "app/camera_path.h"
#include "preview/preview.h"

namespace pxf {

struct PathRenderOptions {
  int spp_per_frame = 1;        // traced frames per path frame
  double time_per_frame_s = 0;  // > 0: instead, trace while the frame's passes fit this budget
  std::string out = "out";
  bool quiet = false;
};

// The file name of path frame `frame`: frame-0000.png, ...
std::string path_frame_name(int frame);

struct PathFrameRecord {
  int samples = 0;     // traced frames of this path frame
  double ms = 0;       // its wall time (camera change, tracing, passes, display)
  bool history = false;  // the reprojected history had weight in it
};

// Renders the frames of `path` in order on one Preview (the camera changes, the history
// reprojects) and calls `on_frame(frame, preview)` after each frame's display. Each frame: the
// camera, the range buffer to convergence (so that the frames do not depend on timing), the traced
// frames, then Preview::finish (the last-frame filter run, blend, tone map). Before each frame after
// the first, `should_stop()` can end the path: the frame under way is always finished.
template <class OnFrame, class ShouldStop>
std::vector<PathFrameRecord> render_path(Preview& preview, const CameraPath& path, const Camera& base,
                                         const PathRenderOptions& options, OnFrame&& on_frame,
                                         ShouldStop&& should_stop);

// The command: PNG frames and DIR/path.json (settings, per-frame samples and times), written as one
// set (app/output_set.h). Ctrl-C, SIGTERM or SIGHUP finishes the frame under way and commits the
// frames done so far, path.json saying "interrupted"; returns the exit status (128 + the signal then).
// Needs a current GL context.
int run_camera_path_render(const Scene& scene, const std::string& scene_name, const PreviewSettings& settings,
                           int width, int height, const CameraPath& path, const PathRenderOptions& options);

}  // namespace pxf

#include "app/camera_path_render_impl.h"
