// pxf explore: command line of the Dear ImGui explorer; the window is app/explorer/explorer.cpp.
#include <cstdio>

#include "app/commands.h"
#include "app/explorer/explorer.h"
#include "app/explorer/explorer_views.h"

namespace pxf {

int run_explore(const Args& args) {
  ExploreOptions o;
  CommandLine cli("explore", "[options]",
                  "Interactive explorer: a window that renders progressively with pixel filtering. Every buffer\n"
                  "viewable (keys 1-0), split view, pixel inspector, live parameters, camera (drag: orbit,\n"
                  "right drag: pan, wheel: zoom, WASD/QE: fly, R: reset), capture (P) into --out DIR with the\n"
                  "same files as `pxf render`. Drop a .gltf/.glb onto the window to load it.");
  add_scene_options(cli, o.scene, /*headless=*/false);
  // The explorer shows every frame: the filter runs on the budget schedule, not on the last frame only.
  o.preview.schedule = FilterSchedule::Budget;
  add_preview_options(cli, o.preview);
  cli.choice("--view", &o.view, buffer_view_names(), "initial buffer view (default final)");
  std::string inspect;
  cli.choice("--split", &o.split, buffer_view_names(), "split view: the --view buffer left, this one right");
  cli.option("--inspect", &inspect, "X,Y", "open the pixel inspector at pixel X,Y");
  cli.option("--spp", &o.spp, "stop path tracing at this many samples per pixel (default: never)", 0, 1 << 24);
  cli.option("--time", &o.time_s,
             "wall-clock budget in seconds of each accumulation (from its start or a camera change), finish included",
             0.001, 1e7);
  cli.option("--zoom", &o.zoom, "display zoom of the image (default: fit the window)", 0, 16);
  cli.option("--out", &o.out, "DIR", "capture folder (default out)");
  cli.option("--frames", &o.frames, "quit after N displayed frames, with --spp or --time not before they are reached (testing)", 0, 1 << 30);
  cli.option("--screenshot", &o.screenshot, "FILE.png", "save the whole window (UI included) before quitting");
  cli.flag("--capture", &o.capture_on_exit, "capture into --out before quitting (with --frames)");
  cli.option("--camera-path", &o.camera_path, "FILE.json|turntable:N",
             "play a camera path (as `pxf render --camera-path`), then hold its last frame");
  cli.option("--spp-per-frame", &o.spp_per_frame, "with --camera-path: samples per path frame (default 1)", 1, 1 << 24);
  if (!cli.parse(args)) return 0;
  if (o.camera_path.empty() && cli.given("--spp-per-frame")) throw UsageError("--spp-per-frame needs --camera-path");
  if (!inspect.empty() && std::sscanf(inspect.c_str(), "%d,%d", &o.inspect_x, &o.inspect_y) != 2)
    throw UsageError("--inspect wants X,Y, got '" + inspect + "'");
  if (print_scene_list_if_asked(o.scene)) return 0;
  o.all_hv_given = cli.given("--all-hv");
  o.filter_given = cli.given("--filter");
  return run_explorer(o);
}

}  // namespace pxf
