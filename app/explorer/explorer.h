// `pxf explore`: the Dear ImGui desktop explorer. A GLFW window that path-traces
// progressively through the shared Preview core, shows every buffer (explorer_views.h), edits the
// parameters live, moves the camera (scene/camera_controls.h), inspects pixels and captures the same
// files as `pxf render`. The only part of pxf that includes ImGui.
#pragma once
#include <string>

#include "app/options.h"

namespace pxf {

struct ExploreOptions {
  SceneOptions scene;
  PreviewSettings preview;  // as the command line set them
  bool all_hv_given = false;  // --all-hv on the command line wins over a loaded scene's default
  bool filter_given = false;  // --filter likewise over kAllHvFilter
  std::string out = "out";    // capture folder
  std::string view = "final"; // initial buffer view (buffer_view_names())
  std::string screenshot;     // PNG of the whole window (UI included), saved before quitting
  int frames = 0;             // quit after this many displayed frames (0 = when the window closes)
  int spp = 0;                // stop path tracing at this many samples (0 = never)
  double time_s = 0;          // stop each accumulation within this wall time, finish included (0 = never)
  int zoom = 0;               // display zoom of the image (0 = fit the window)
  bool capture_on_exit = false;
  std::string split;          // split view: the --view buffer left, this one right ("" = no split)
  int inspect_x = -1, inspect_y = -1;  // show the pixel inspector at this pixel (screenshots, tests)
  std::string camera_path;    // play this path (app/camera_path.h: FILE.json or turntable:N), then hold its last frame
  int spp_per_frame = 1;      // traced frames per path frame
};

// Opens the window and runs until it is closed (or options.frames have been shown). Throws
// pxf::Error when the first scene or the window cannot be set up.
int run_explorer(ExploreOptions& options);

}  // namespace pxf
