#include "app/camera_path_render.h"

#include <cstdio>

#include <nlohmann/json.hpp>

#include "app/output_set.h"
#include "app/stop_signal.h"
#include "image/image.h"

namespace pxf {

std::string path_frame_name(int frame) {
  char name[32];
  std::snprintf(name, sizeof name, "frame-%04d.png", frame);
  return name;
}

namespace {

nlohmann::json path_json(const std::string& scene, int width, int height, const PathRenderOptions& options,
                         const PreviewSettings& settings, const std::vector<PathFrameRecord>& records,
                         int frames_planned) {
  nlohmann::json j;
  j["scene"] = scene;
  j["frames_planned"] = frames_planned;
  j["interrupted"] = static_cast<int>(records.size()) < frames_planned;
  j["width"] = width;
  j["height"] = height;
  j["spp_per_frame"] = options.time_per_frame_s > 0 ? nlohmann::json(nullptr) : nlohmann::json(options.spp_per_frame);
  j["time_per_frame_s"] = options.time_per_frame_s;
  j["motion_history"] = settings.motion_history;
  j["filter"] = filter_option_names()[static_cast<int>(settings.filter.kind)];
  nlohmann::json frames = nlohmann::json::array();
  for (size_t f = 0; f < records.size(); ++f)
    frames.push_back({{"file", path_frame_name(static_cast<int>(f))},
                      {"samples", records[f].samples},
                      {"ms", records[f].ms},
                      {"history", records[f].history}});
  j["frames"] = frames;
  return j;
}

}  // namespace

int run_camera_path_render(const Scene& scene, const std::string& scene_name, const PreviewSettings& settings,
                           int width, int height, const CameraPath& path, const PathRenderOptions& options) {
  const StopSignalHandlers stop_handlers;  // kept through the commit: a stop then still gives 128 + signal
  std::vector<std::string> names;
  for (int f = 0; f < path.frame_count(); ++f) names.push_back(path_frame_name(f));
  names.push_back("path.json");
  OutputSetWriter writer(options.out, names);
  Preview preview(scene, settings, width, height);
  const int total = path.frame_count();
  std::vector<std::string> written;
  const std::vector<PathFrameRecord> records = render_path(
      preview, path, scene.camera, options,
      [&](int frame, Preview& p) {
        const Image display = p.display_image();
        if (count_nonfinite(display) > 0) throw Error("frame " + std::to_string(frame) + " has non-finite values (a bug)");
        write_png(writer.staging() + "/" + path_frame_name(frame), display);
        written.push_back(path_frame_name(frame));
        if (!options.quiet) std::fprintf(stderr, "\rframe %d/%d", frame + 1, total);
      },
      [] { return stop_signal() != 0; });
  if (!options.quiet) std::fputc('\n', stderr);
  const std::string text = path_json(scene_name, width, height, options, settings, records, total).dump(2) + "\n";
  write_file_completely(writer.staging() + "/path.json", text.data(), text.size());
  written.push_back("path.json");
  writer.set_names(written);
  writer.commit();
  const int done = static_cast<int>(records.size());
  double ms = 0;
  for (const PathFrameRecord& r : records) ms += r.ms;
  std::printf("%s: %dx%d, %d of %d path frames%s, %.2f s (%.0f ms a frame); wrote %s/frame-0000.png ... %s and "
              "%s/path.json\n",
              scene_name.c_str(), width, height, done, total, done < total ? " (interrupted)" : "", ms / 1000.0,
              ms / done, options.out.c_str(), path_frame_name(done - 1).c_str(), options.out.c_str());
  return stop_signal() ? 128 + stop_signal() : 0;
}

}  // namespace pxf
