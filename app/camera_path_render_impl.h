// render_path's body (a template: the caller passes its own per-frame work and stop test).
#pragma once
#include "core/timing.h"

namespace pxf {

template <class OnFrame, class ShouldStop>
std::vector<PathFrameRecord> render_path(Preview& preview, const CameraPath& path, const Camera& base,
                                         const PathRenderOptions& options, OnFrame&& on_frame,
                                         ShouldStop&& should_stop) {
  std::vector<PathFrameRecord> records;
  for (int frame = 0; frame < path.frame_count() && (frame == 0 || !should_stop()); ++frame) {
    const auto start = BenchClock::now();
    preview.set_camera(camera_on_path(path, frame, base));
    preview.converge_range_buffer();
    PathFrameRecord record;
    const double budget_ms = options.time_per_frame_s * 1000.0;
    for (int i = 0; budget_ms > 0 || i < options.spp_per_frame; ++i) {
      if (i > 0 && budget_ms > 0 && !next_frame_fits(preview.predict_next_frame(budget_ms, elapsed_ms(start)))) break;
      if (i == 0) record.history = preview.history_active();
      preview.add_frame(false, false);
    }
    preview.finish();
    record.samples = preview.samples();
    record.ms = elapsed_ms(start);
    records.push_back(record);
    on_frame(frame, preview);
  }
  return records;
}

}  // namespace pxf
