#include "app/render_output.h"
#include "core/timing.h"

#include <pthread.h>
#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

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
  j["settings"] = {{"scene", r.scene->scene},
                   {"env", r.scene->env},
                   {"width", preview.width()},
                   {"height", preview.height()},
                   {"spp", preview.samples()},
                   {"threshold", s.threshold},
                   {"filter", filter_kind_name(s.filter.kind)},
                   {"demodulate", s.demodulate},
                   {"bias_guard", s.bias_guard},
                   {"schedule", filter_schedule_names()[static_cast<int>(s.schedule)]},
                   {"sigma_s", s.filter.sigma_s},
                   {"sigma_shrink", s.shrink_sigma},
                   {"sigma_c", s.filter.sigma_c},
                   {"sigma_d", s.filter.sigma_d},
                   {"seed", s.trace.seed},
                   {"sampler", sampler_type_names()[static_cast<int>(s.trace.sampler)]},
                   {"threads", s.trace.threads},
                   {"max_vertices", s.trace.max_vertices},
                   {"rr_start_vertex", s.trace.rr_start_vertex},
                   {"all_hv", s.trace.all_hv},
                   {"specular_sampling", s.trace.specular_sampling},
                   {"near_specular_sampling", s.trace.near_specular_sampling},
                   {"key", s.tonemap.key},
                   {"gl", r.gl_backend},
                   {"stage_timing", gl_timing_names()[static_cast<int>(gl_timing())]},
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
  j["filter_last_sigma_s"] = preview.last_sigma_s();
  j["filter_stopped_all_case2"] = preview.filter_stopped();
  j["filter_runs_skipped_low_hv"] = preview.filter_runs_skipped_low_hv();
  j["hv_energy_share"] = hv_energy_share(preview.renderer().accumulation());
  j["nan_samples_dropped"] = trace.nan_samples_dropped;
  j["interrupted"] = r.interrupted;
  const auto& counts = preview.case_counts();
  j["blend_case_pixels"] = {{"no_filtered", counts[kCaseNoFiltered]}, {"case1", counts[kCaseFilteredOnly]},
                            {"case2", counts[kCaseUnfiltered]},       {"case3", counts[kCaseMixed]},
                            {"unknown_variance", counts[kCaseUnknownVar]}, {"bias_guard", counts[kCaseBiasGuard]}};
  if (r.final_vs_reference) j["final_vs_reference"] = metrics_json(*r.final_vs_reference);
  if (r.unfiltered_vs_reference) j["unfiltered_vs_reference"] = metrics_json(*r.unfiltered_vs_reference);
  return j;
}

}  // namespace

namespace {

namespace fs = std::filesystem;

const char* const kOutputNames[] = {"final.png", "final.exr", "buffers.exr", "stats.json"};
const std::string kStagingPrefix = ".pxf-staging-";

// The pid in "NAME.tmp-PID" or ".pxf-staging-PID", or 0.
pid_t pid_suffix(const std::string& name) {
  size_t at = std::string::npos;
  if (name.rfind(kStagingPrefix, 0) == 0) at = kStagingPrefix.size();
  else if (const size_t tmp = name.rfind(".tmp-"); tmp != std::string::npos) at = tmp + 5;
  if (at == std::string::npos || at >= name.size() || name.find_first_not_of("0123456789", at) != std::string::npos)
    return 0;
  return static_cast<pid_t>(std::stol(name.substr(at)));
}

bool process_is_gone(pid_t pid) { return pid > 0 && pid != ::getpid() && ::kill(pid, 0) != 0 && errno == ESRCH; }

// Staging folders and temporary files that a killed pxf (SIGKILL, power loss) left behind.
void remove_stale_temporaries(const std::string& dir) {
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec))
    if (process_is_gone(pid_suffix(entry.path().filename().string()))) fs::remove_all(entry.path(), ec);
}

// Blocks the stop signals while the output set is replaced, so that a Ctrl-C or SIGTERM arriving
// then takes effect only once every file is in place (the handlers stay as they are).
class StopSignalsBlocked {
 public:
  StopSignalsBlocked() {
    sigset_t stop;
    sigemptyset(&stop);
    for (int s : {SIGINT, SIGTERM, SIGHUP, SIGQUIT}) sigaddset(&stop, s);
    pthread_sigmask(SIG_BLOCK, &stop, &previous_);
  }
  ~StopSignalsBlocked() { pthread_sigmask(SIG_SETMASK, &previous_, nullptr); }

 private:
  sigset_t previous_;
};

void write_outputs_into(const std::string& staging, Preview& preview, RenderReport& report,
                        const std::vector<Layer>& buffers) {
  write_png(staging + "/final.png", preview.display_image());
  write_exr(staging + "/final.exr", layer_image(buffers, "final"));
  write_exr(staging + "/buffers.exr", buffers);
  const std::string text = stats_json(preview, report).dump(2) + "\n";
  write_file_completely(staging + "/stats.json", text.data(), text.size());
}

// The new set replaces the old one only once it is complete. The old files go first, so that a
// kill in between leaves part of one run's set, never a mix of two runs.
void replace_output_set(const std::string& staging, const std::string& dir) {
  std::error_code ec;
  for (const char* name : kOutputNames) {
    fs::remove(dir + "/" + name, ec);
    if (ec) throw Error(dir + "/" + name + ": cannot replace: " + ec.message());
  }
  sync_folder(dir);
  for (const char* name : kOutputNames) {
    fs::rename(staging + "/" + name, dir + "/" + name, ec);
    if (ec) throw Error(dir + "/" + name + ": cannot move into place: " + ec.message());
  }
  sync_folder(dir);
}

}  // namespace

void check_reference(const std::string& path, int width, int height) {
  const Image reference = read_exr(path);
  if (reference.width != width || reference.height != height)
    throw Error(path + ": the reference is " + std::to_string(reference.width) + "x" + std::to_string(reference.height) +
                ", the render " + std::to_string(width) + "x" + std::to_string(height));
}

void write_render_outputs(const std::string& dir, Preview& preview, RenderReport& report) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw Error(dir + ": cannot create output folder: " + ec.message());
  remove_stale_temporaries(dir);
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
  const StopSignalsBlocked blocked;
  const std::string staging = dir + "/" + kStagingPrefix + std::to_string(::getpid());
  fs::remove_all(staging, ec);
  fs::create_directory(staging, ec);
  if (ec) throw Error(staging + ": cannot create: " + ec.message());
  try {
    write_outputs_into(staging, preview, report, buffers);
    replace_output_set(staging, dir);
  } catch (...) {
    fs::remove_all(staging, ec);
    throw;
  }
  fs::remove_all(staging, ec);
}

}  // namespace pxf
