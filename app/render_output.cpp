#include "app/render_output.h"
#include "pathtracer/bench.h"

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "gl/context.h"

namespace pxf {

const Image& layer_image(const std::vector<Layer>& buffers, const std::string& name) {
  for (const Layer& l : buffers)
    if (l.name == name) return l.image;
  throw Error("no buffer named '" + name + "'");
}

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
  j["settings"] = {{"scene", r.scene->scene},
                   {"env", r.scene->env},
                   {"width", preview.width()},
                   {"height", preview.height()},
                   {"spp", preview.samples()},
                   {"threshold", s.threshold},
                   {"filter", filter_option_name(s)},
                   {"schedule", r.preview->schedule},
                   {"sigma_s", s.filter.sigma_s},
                   {"sigma_c", s.filter.sigma_c},
                   {"sigma_d", s.filter.sigma_d},
                   {"seed", s.trace.seed},
                   {"threads", s.trace.threads},
                   {"max_vertices", s.trace.max_vertices},
                   {"rr_start_vertex", s.trace.rr_start_vertex},
                   {"all_hv", s.trace.all_hv},
                   {"key", s.tonemap.key},
                   {"gl", r.gl_backend},
                   {"gl_renderer", r.gl_renderer}};
  j["stage_ms_total"] = times_json(total);
  j["stage_ms_per_frame"] = {{"path_tracing", preview.samples() ? total.path_tracing / preview.samples() : 0.0}};
  j["wall_ms"] = r.wall_ms;
  j["time_budget"] = {{"budget_ms", r.budget_ms}, {"used_ms", r.used_ms}, {"spp_reached", preview.samples()}};
  j["share_outside_path_tracing"] = share_outside_tracing(total, r.used_ms > 0 ? r.used_ms : r.wall_ms);
  j["filter_range_share_of_tracing"] = pass_share_of_tracing(total);
  j["load_ms"] = r.load_ms;
  j["peak_memory_mib"] = peak_memory_mib();
  j["paths_per_second"] = total.path_tracing > 0 ? trace.paths / (total.path_tracing / 1000.0) : 0.0;
  j["rays"] = trace.rays;
  j["filter_runs"] = preview.filter_runs();
  j["filter_stopped_all_case2"] = preview.filter_stopped();
  j["nan_samples_dropped"] = trace.nan_samples_dropped;
  j["interrupted"] = r.interrupted;
  const auto& counts = preview.case_counts();
  j["blend_case_pixels"] = {{"no_filtered", counts[kCaseNoFiltered]}, {"case1", counts[kCaseFilteredOnly]},
                            {"case2", counts[kCaseUnfiltered]},       {"case3", counts[kCaseMixed]},
                            {"unknown_variance", counts[kCaseUnknownVar]}};
  if (r.final_vs_reference) j["final_vs_reference"] = metrics_json(*r.final_vs_reference);
  if (r.unfiltered_vs_reference) j["unfiltered_vs_reference"] = metrics_json(*r.unfiltered_vs_reference);
  return j;
}

}  // namespace

void write_render_outputs(const std::string& dir, Preview& preview, RenderReport& report) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw Error(dir + ": cannot create output folder: " + ec.message());
  const std::vector<Layer> buffers = preview.buffers();
  for (const Layer& l : buffers)
    if (count_nonfinite(l.image) > 0) throw Error("buffer '" + l.name + "' has non-finite values (a bug)");
  if (!report.reference_path.empty()) {
    const Image reference = read_exr(report.reference_path);
    report.final_vs_reference = compare_images(layer_image(buffers, "final"), reference);
    report.unfiltered_vs_reference = compare_images(unfiltered_image(buffers), reference);
  }
  write_png(dir + "/final.png", preview.display_image());
  write_exr(dir + "/final.exr", layer_image(buffers, "final"));
  write_exr(dir + "/buffers.exr", buffers);
  const std::string text = stats_json(preview, report).dump(2) + "\n";
  write_file_atomically(dir + "/stats.json", [&](const std::string& tmp) {
    std::ofstream out(tmp);
    out << text;
    if (!out) throw Error(dir + "/stats.json: cannot write");
  });
}

}  // namespace pxf
