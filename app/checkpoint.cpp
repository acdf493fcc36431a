#include "app/checkpoint.h"

#include <cstdio>
#include <filesystem>

namespace pxf {

namespace {

// "A:B" or "i/n" as two unsigned numbers; false when malformed.
bool parse_pair(const std::string& text, char separator, uint32_t& a, uint32_t& b) {
  unsigned long long x = 0, y = 0;
  char sep = 0, extra = 0;
  const std::string format = std::string("%llu%c%llu%c");
  if (std::sscanf(text.c_str(), format.c_str(), &x, &sep, &y, &extra) != 3 || sep != separator) return false;
  if (text.empty() || text[0] == '-' || text.find(std::string(1, separator) + "-") != std::string::npos) return false;
  if (x > UINT32_MAX || y > UINT32_MAX) return false;
  a = static_cast<uint32_t>(x);
  b = static_cast<uint32_t>(y);
  return true;
}

}  // namespace

void add_checkpoint_options(CommandLine& cli, CheckpointOptions& o) {
  cli.option("--checkpoint", &o.interval_s, "save the accumulation to DIR/state.pxfs at most every SECONDS, on Ctrl-C "
             "and at the end", 0.0, 1e9);
  cli.option("--resume", &o.resume, "STATE", "continue a render from its saved state up to --spp (or --frames' end)");
  cli.option("--frames", &o.frames, "A:B", "trace only frames A..B-1 (a shard; combine shards with pxf merge)");
  cli.option("--shard", &o.shard, "i/n", "trace the i-th (0-based) of n parts of the --spp frames");
}

std::string state_path(const std::string& out_dir) { return out_dir + "/state.pxfs"; }

bool uses_state(const CheckpointOptions& o) {
  return o.interval_s > 0 || !o.resume.empty() || !o.frames.empty() || !o.shard.empty();
}

FrameRange render_frame_range(const CheckpointOptions& o, int spp) {
  if (!o.frames.empty() && !o.shard.empty()) throw UsageError("--frames and --shard exclude each other");
  FrameRange range{0, static_cast<uint32_t>(spp)};
  if (!o.frames.empty()) {
    if (!parse_pair(o.frames, ':', range.begin, range.end) || range.begin >= range.end)
      throw UsageError("--frames wants A:B with A < B, got '" + o.frames + "'");
    if (range.count() > kMaxRenderFrames)
      throw UsageError("--frames " + o.frames + " is " + std::to_string(range.count()) + " frames; one render traces at most " +
                       std::to_string(kMaxRenderFrames) + " (like --spp; split it into shards)");
  } else if (!o.shard.empty()) {
    uint32_t i = 0, n = 0;
    if (!parse_pair(o.shard, '/', i, n) || n == 0 || i >= n)
      throw UsageError("--shard wants i/n with 0 <= i < n, got '" + o.shard + "'");
    range = FrameRange{static_cast<uint32_t>(uint64_t(spp) * i / n), static_cast<uint32_t>(uint64_t(spp) * (i + 1) / n)};
    if (range.begin == range.end) throw UsageError("--shard " + o.shard + " of " + std::to_string(spp) + " spp is empty");
  }
  return range;
}

SampleSettings render_sample_settings(const SceneOptions& scene, const PreviewSettings& settings) {
  SampleSettings s = sample_settings(scene_content_hash(scene.scene, scene.env, scene.env_strength), scene.width,
                                     scene.height, settings.trace);
  s.adaptive = !settings.adaptive ? 0u : settings.adaptive_params.goal == AdaptiveGoal::Clean ? 2u : 1u;
  return s;
}

void apply_sample_settings(const SampleSettings& s, SceneOptions& scene, PreviewSettings& preview) {
  scene.width = static_cast<int>(s.width);
  scene.height = static_cast<int>(s.height);
  preview.trace.seed = s.seed;
  preview.trace.max_vertices = s.max_vertices;
  preview.trace.rr_start_vertex = s.rr_start_vertex;
  preview.trace.all_hv = s.all_hv != 0;
  preview.trace.sampler = static_cast<SamplerType>(s.sampler);
  preview.trace.replicates = static_cast<int>(s.replicates);
  preview.adaptive = s.adaptive != 0;
  if (s.adaptive != 0) preview.adaptive_params.goal = s.adaptive == 2 ? AdaptiveGoal::Clean : AdaptiveGoal::Error;
  preview.trace.guiding = static_cast<GuidingMode>(s.guiding);
  preview.trace.environment_visibility = s.environment_visibility != 0;
  preview.trace.split_halves = s.split_halves != 0;
  const auto mode = static_cast<SpecularSamplingMode>(s.specular_sampling);
  preview.trace.specular_sampling = mode == SpecularSamplingMode::All;
  preview.trace.specular_chains = mode == SpecularSamplingMode::Chains;
}

Checkpointer::Checkpointer(const CheckpointOptions& options, const std::string& out_dir,
                           const SampleSettings& settings, FrameRange range)
    : options_(options),
      path_(state_path(out_dir)),
      settings_(settings),
      range_(range),
      enabled_(uses_state(options)),
      last_write_(std::chrono::steady_clock::now()) {}

void Checkpointer::start(Preview& preview) const {
  if (options_.resume.empty()) {
    preview.set_first_frame(range_.begin);
    return;
  }
  const AccumulationState state = read_state_file(options_.resume);
  const std::string diff = state.settings.difference(settings_);
  if (!diff.empty()) throw Error(options_.resume + ": the state belongs to another render: " + diff);
  if (state.frames.size() != 1 || state.frames[0].begin != range_.begin || state.frames[0].end > range_.end)
    throw Error(options_.resume + ": the state holds frames " + frame_ranges_text(state.frames) +
                ", which do not start this render's frames " + frame_ranges_text({range_}));
  const std::string no_field = options_.resume + ": the state holds no guiding field (a merge of guided shards), so it "
                               "cannot be continued exactly";
  const bool guiding_on = state.settings.guiding == static_cast<uint32_t>(GuidingMode::On);
  if (guiding_on && state.guiding_field.empty()) throw Error(no_field);
  preview.load_state(state);
  // Auto: a render that had started guiding by the frames saved (its visibility field's verdict)
  // restarts it at once when the state has no field.
  if (state.guiding_field.empty() && preview.renderer().guiding_active()) throw Error(no_field);
}

AccumulationState Checkpointer::state_of(const Preview& preview) const {
  AccumulationState state;
  state.settings = settings_;
  const uint32_t first = preview.renderer().first_frame();
  state.frames = {FrameRange{first, first + static_cast<uint32_t>(preview.samples())}};
  state.acc = preview.renderer().accumulation();
  state.traced = preview.pixel_samples();
  if (settings_.guiding) state.guiding_field = preview.renderer().guiding_field();
  if (settings_.environment_visibility) state.environment_visibility = preview.renderer().environment_visibility();
  if (settings_.adaptive) {
    const size_t pixels = state.traced.size();
    state.rate = preview.allocation_rates_now();
    state.rate.resize(pixels, 0.0f);  // 0: no allocation yet
    state.credit = preview.allocation_credit();
    state.credit.resize(pixels, 0.0f);  // no allocation yet (warm-up): every credit 0
    state.next_active = preview.next_active();
    state.next_active.resize(pixels, uint8_t{1});  // empty = every pixel
  }
  return state;
}

void Checkpointer::maybe_write(const Preview& preview) {
  if (options_.interval_s <= 0) return;
  const auto now = std::chrono::steady_clock::now();
  if (std::chrono::duration<double>(now - last_write_).count() < options_.interval_s) return;
  // A failed periodic write (a full disk) loses nothing: the atomic write leaves the previous
  // state in place, and the final write tries again. So the render goes on, with one warning.
  try {
    write(preview);
  } catch (const Error& e) {
    last_write_ = std::chrono::steady_clock::now();  // the next try after another interval
    if (!warned_) std::fprintf(stderr, "pxf: warning: periodic state not saved, rendering on: %s\n", e.what());
    warned_ = true;
  }
}

void Checkpointer::write(const Preview& preview) {
  if (!enabled_ || preview.samples() == 0) return;
  const auto start = std::chrono::steady_clock::now();
  std::error_code ignored;  // a folder that cannot be made fails the write below with its name
  std::filesystem::create_directories(std::filesystem::path(path_).parent_path(), ignored);
  written_ = false;  // until this write succeeds, the file on disk is not the state of these samples
  write_state_file(path_, state_of(preview));
  written_ = true;
  last_write_ = std::chrono::steady_clock::now();
  write_ms_ += std::chrono::duration<double, std::milli>(last_write_ - start).count();
}

std::string Checkpointer::write_final(const Preview& preview) {
  try {
    write(preview);
    return "";
  } catch (const Error& e) {
    return e.what();
  }
}

}  // namespace pxf
