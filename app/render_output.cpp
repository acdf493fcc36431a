#include "app/render_output.h"

#include "preview/setting_table.h"
#include "core/timing.h"

#include <filesystem>
#include <nlohmann/json.hpp>

#include "app/checkpoint.h"
#include "app/output_set.h"
#include "gl/context.h"

namespace pxf {

Image unfiltered_image(const std::vector<Layer>& buffers) {
  Image sum = layer_image(buffers, "lv");
  const Image& hv = layer_image(buffers, "hv");
  for (size_t i = 0; i < sum.pixels.size(); ++i) sum.pixels[i] += hv.pixels[i];
  return sum;
}

namespace {

nlohmann::json metrics_json(const ImageMetrics& m) {
  return {{"nrmse_percent", m.nrmse_percent}, {"rmse", m.rmse},           {"rel_mse", m.rel_mse},
          {"max_abs_diff", m.max_abs_diff},   {"nan_count", m.nan_count}, {"inf_count", m.inf_count}};
}

nlohmann::json times_json(const StageTimes& t) {
  return {{"path_tracing", t.path_tracing}, {"upload", t.upload}, {"range", t.range}, {"filter", t.filter},
          {"blend", t.blend},               {"tonemap", t.tonemap}, {"total", t.total()}};
}

nlohmann::json stats_json(Preview& preview, const RenderReport& r) {
  const PreviewSettings& s = preview.settings();
  const TraceStats& trace = preview.renderer().stats();
  const StageTimes& total = preview.total_times();
  nlohmann::json j;
  j["settings"] = settings_json(s);  // every preview setting (app/setting_table.h)
  j["settings"].update({{"scene", r.scene->scene},
                        {"env", r.scene->env},
                        {"width", preview.width()},
                        {"height", preview.height()},
                        {"spp", preview.samples()},
                        {"gl", r.gl_backend},
                        {"stage_timing", gl_timing_names()[static_cast<int>(gl_timing())]},
                        {"gl_renderer", r.gl_renderer}});
  j["stage_ms_total"] = times_json(total);
  j["stage_ms_per_frame"] = {{"path_tracing", preview.samples() ? total.path_tracing / preview.samples() : 0.0}};
  j["wall_ms"] = r.wall_ms;
  j["time_budget"] = {{"budget_ms", r.budget_ms}, {"used_ms", r.used_ms}, {"spp_reached", preview.samples()}};
  j["share_outside_path_tracing"] = share_outside_tracing(total, r.used_ms > 0 ? r.used_ms : r.wall_ms);
  j["filter_range_share_of_tracing"] = pass_share_of_tracing(total);
  j["load_ms"] = r.load_ms;
  j["peak_memory_mib"] = peak_memory_mib();
  // docs/guiding.md: under --guiding auto, whether it started, and the field's size.
  j["guiding_active"] = preview.renderer().guiding_active();
  if (preview.renderer().guiding_active()) j["guiding_field_bytes"] = preview.renderer().guiding_memory_bytes();
  // Light through openings: the regions that sample what they learned of the visible sky (docs/sampling.md).
  if (s.trace.environment_visibility) j["environment_visibility_regions"] = preview.renderer().environment_visibility_regions();
  // The loader's estimate (docs/robustness.md), beside the peak it bounds: 0 for a built-in scene.
  j["estimated_load_mib"] = preview.renderer().scene().estimated_load_bytes / (1024.0 * 1024.0);
  j["paths_per_second"] = total.path_tracing > 0 ? trace.paths / (total.path_tracing / 1000.0) : 0.0;
  j["rays"] = trace.rays;
  j["filter_runs"] = preview.filter_runs();
  j["filter_last_sigma_s"] = preview.last_sigma_s();
  j["filter_stopped_all_case2"] = preview.filter_stopped();
  j["filter_runs_skipped_low_hv"] = preview.filter_runs_skipped_low_hv();
  j["hv_energy_share"] = hv_energy_share(preview.renderer().accumulation());
  j["nan_samples_dropped"] = trace.nan_samples_dropped;
  // Paths per pixel: spp for a uniform render; with --adaptive each pixel's own count.
  const SampleCounts paths = sample_counts(preview.pixel_samples());
  j["samples_per_pixel"] = {{"mean", paths.mean}, {"min", paths.min}, {"max", paths.max}};
  j["interrupted"] = r.interrupted;
  // Clean: the final blend shows every pixel in case 2, the unbiased image at threshold t, or no
  // filter ran and none was needed (Preview::clean).
  j["clean"] = preview.clean();
  j["until_clean"] = {{"requested", r.until_clean},
                      {"time_to_clean_ms", r.clean_ms >= 0 ? nlohmann::json(r.clean_ms) : nlohmann::json(nullptr)},
                      {"case2_share_over_time", r.case2_share_over_time}};
  const auto& counts = preview.case_counts();
  j["blend_case_pixels"] = {{"no_filtered", counts[kCaseNoFiltered]}, {"case1", counts[kCaseLeastVariance]},
                            {"case2", counts[kCaseUnfiltered]},       {"case3", counts[kCaseMixed]},
                            {"unknown_variance", counts[kCaseUnknownVar]}, {"bias_guard", counts[kCaseBiasGuard]}};
  if (r.final_vs_reference) j["final_vs_reference"] = metrics_json(*r.final_vs_reference);
  if (r.unfiltered_vs_reference) j["unfiltered_vs_reference"] = metrics_json(*r.unfiltered_vs_reference);
  return j;
}

}  // namespace

namespace {

const std::vector<std::string> kOutputNames = {"final.png", "final.exr", "buffers.exr", "stats.json"};

void write_outputs_into(const std::string& staging, Preview& preview, RenderReport& report,
                        const std::vector<Layer>& buffers) {
  write_png(staging + "/final.png", preview.display_image());
  write_exr(staging + "/final.exr", layer_image(buffers, "final"));
  write_exr(staging + "/buffers.exr", buffers);
  const std::string text = stats_json(preview, report).dump(2) + "\n";
  write_file_completely(staging + "/stats.json", text.data(), text.size());
}

}  // namespace

void check_reference(const std::string& path, int width, int height) {
  const Image reference = read_exr(path);
  if (reference.width != width || reference.height != height)
    throw Error(path + ": the reference is " + std::to_string(reference.width) + "x" + std::to_string(reference.height) +
                ", the render " + std::to_string(width) + "x" + std::to_string(height));
}

void write_render_outputs(const std::string& dir, Preview& preview, RenderReport& report) {
  const std::vector<Layer> buffers = preview.buffers();
  for (const Layer& l : buffers)
    if (count_nonfinite(l.image) > 0)
      throw Error((report.scene ? report.scene->scene + ": " : "") + "buffer '" + l.name +
                  "' has non-finite values (a bug)");
  if (!report.reference_path.empty()) {
    const Image reference = read_exr(report.reference_path);
    report.final_vs_reference = compare_images(layer_image(buffers, "final"), reference);
    report.unfiltered_vs_reference = compare_images(unfiltered_image(buffers), reference);
  }
  OutputSetWriter writer(dir, kOutputNames);
  write_outputs_into(writer.staging(), preview, report, buffers);
  writer.commit();
  // The checkpoint's state file is no part of the set, but a killed write of it leaves its
  // temporary in the same folder.
  remove_stale_temporaries(dir, {std::filesystem::path(state_path(dir)).filename().string()});
}

}  // namespace pxf
