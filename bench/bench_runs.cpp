#include "bench/bench_runs.h"

#include "core/timing.h"
#include "image/metrics.h"
#include "preview/adaptive.h"

namespace pxf {

RowError row_error(const Image& test, const Image& reference) {
  const DisplayMetrics m = compare_display(test, reference);
  return {m.hdr.nrmse_percent, m.display_nrmse_percent, m.flip_mean};
}

TimedRun run_timed(const Scene& scene, const PreviewSettings& settings, int width, int height, double budget_ms,
                   const Image& reference) {
  const auto start = BenchClock::now();
  Preview preview(scene, settings, width, height);
  for (int i = 0;; ++i) {
    if (i > 0 && !next_frame_fits(preview.predict_next_frame(budget_ms, elapsed_ms(start)))) break;
    preview.add_frame(false, /*display=*/i == 0);  // the first display measures the finish's
  }
  preview.finish();
  TimedRun run;
  run.used_ms = elapsed_ms(start);
  run.image = preview.final_image();
  run.unfiltered = preview.renderer().unfiltered_image();
  run.spp = preview.samples();
  run.paths_per_pixel = sample_counts(preview.pixel_samples()).mean;
  run.filter_runs = preview.filter_runs();
  run.times = preview.total_times();
  run.error = row_error(preview.final_image(), reference);
  return run;
}

}  // namespace pxf
