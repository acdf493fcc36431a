// pxf merge: combines the saved states of render shards (pxf render --frames / --shard) exactly and
// runs the passes (range, filter, blend, tone map) on the merged accumulation.
#include <chrono>
#include <cstdio>

#include "app/checkpoint.h"
#include "app/commands.h"
#include "app/options.h"
#include "app/render_output.h"
#include "gl/context.h"
#include "preview/preview.h"

namespace pxf {

int run_merge(const Args& args) {
  SceneOptions scene_options;
  PreviewSettings preview_settings;
  std::vector<std::string> state_paths;
  std::string out = "out";
  CommandLine cli("merge", "STATE... --scene SCENE [options]",
                  "Combines the states (DIR/state.pxfs) of renders of disjoint frame ranges of one scene\n"
                  "(pxf render --frames A:B or --shard i/n) into one accumulation, then runs range, filter,\n"
                  "blend and tone map on it and writes DIR/final.png, final.exr, buffers.exr, stats.json and\n"
                  "the merged DIR/state.pxfs. Size, seed and path-tracing settings come from the states.");
  cli.positional_list("STATE...", &state_paths, "state files of the shards");
  add_scene_options(cli, scene_options, /*headless=*/true);
  add_preview_options(cli, preview_settings);
  cli.option("--out", &out, "DIR", "output folder (default out)");
  if (!cli.parse(args)) return 0;

  const auto start = std::chrono::steady_clock::now();
  std::vector<AccumulationState> states;
  for (const std::string& path : state_paths) states.push_back(read_state_file(path));
  const AccumulationState merged = merge_states(states);
  const double merge_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();

  Scene scene = load_scene_for(scene_options, preview_settings, cli);
  apply_sample_settings(merged.settings, scene_options, preview_settings);
  const SampleSettings here = render_sample_settings(scene_options, preview_settings);
  const std::string diff = merged.settings.difference(here);
  if (!diff.empty()) throw Error("the states were not rendered from this scene: " + diff);

  set_gl_timing(scene_options.stage_timing);
  auto context = create_gl_context(parse_gl_backend(scene_options.gl));
  Preview preview(scene, preview_settings, scene_options.width, scene_options.height);
  preview.load_state(merged);
  preview.finish();

  RenderReport report;
  report.scene = &scene_options;
  report.gl_backend = context->backend_name();
  report.gl_renderer = context->gl_renderer();
  report.wall_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  write_render_outputs(out, preview, report);
  write_state_file(state_path(out), merged);
  std::printf("merged %zu states (frames %s, %u spp) in %.0f ms; %.2f s in all\n", states.size(),
              frame_ranges_text(merged.frames).c_str(), merged.frame_count(), merge_ms, report.wall_ms / 1000.0);
  std::printf("wrote %s/final.png, %s/final.exr, %s/buffers.exr, %s/stats.json, %s\n", out.c_str(), out.c_str(),
              out.c_str(), out.c_str(), state_path(out).c_str());
  return 0;
}

}  // namespace pxf
