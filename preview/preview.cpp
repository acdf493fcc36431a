#include "preview/preview.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/memory.h"
#include "core/timing.h"
#include "preview/setting_table.h"

namespace pxf {

namespace {

// The filter's parameters that are not settings (FilterParams fields the benches set).
bool same_internal_filter_params(const FilterParams& a, const FilterParams& b) {
  return a.skip_case2 == b.skip_case2 && a.subsampled_taps == b.subsampled_taps;
}
}  // namespace

const std::vector<std::string>& filter_option_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n = filter_kind_names();
    n.push_back(filter_kind_name(FilterKind::None));
    return n;
  }();
  return names;
}

StageTimes& StageTimes::operator+=(const StageTimes& o) {
  path_tracing += o.path_tracing;
  upload += o.upload;
  range += o.range;
  filter += o.filter;
  blend += o.blend;
  tonemap += o.tonemap;
  return *this;
}

StageTimes StageTimes::operator-(const StageTimes& o) const {
  StageTimes d = *this;
  d.path_tracing -= o.path_tracing;
  d.upload -= o.upload;
  d.range -= o.range;
  d.filter -= o.filter;
  d.blend -= o.blend;
  d.tonemap -= o.tonemap;
  return d;
}

double share_outside_tracing(const StageTimes& t, double wall_ms) {
  return wall_ms > 0 ? std::max(0.0, wall_ms - t.path_tracing) / wall_ms : 0.0;
}

double pass_share_of_tracing(const StageTimes& t) {
  return t.path_tracing > 0 ? (t.filter + t.range) / t.path_tracing : 0.0;
}

double hv_energy_share(const Accumulation& acc) {
  double hv = 0, all = 0;
  for (size_t i = 0; i < acc.hv_mean.size(); ++i) {
    const double y_hv = std::max(0.0f, luminance(acc.hv_mean[i].x, acc.hv_mean[i].y, acc.hv_mean[i].z));
    hv += y_hv;
    all += y_hv + std::max(0.0f, luminance(acc.lv_mean[i].x, acc.lv_mean[i].y, acc.lv_mean[i].z));
  }
  return all > 0 ? hv / all : 0.0;
}

uint64_t preview_bytes(int width, int height) {
  return static_cast<uint64_t>(std::max(width, 0)) * static_cast<uint64_t>(std::max(height, 0)) * kPreviewBytesPerPixel;
}

void check_preview_memory(int width, int height, uint64_t available_bytes) {
  const uint64_t needed = preview_bytes(width, height);
  if (available_bytes == 0 || needed <= available_bytes) return;  // 0: unknown, do not refuse
  constexpr double kGiB = 1024.0 * 1024.0 * 1024.0;
  char text[200];
  std::snprintf(text, sizeof text, "--size %dx%d needs about %.1f GiB for the render's buffers (%d B per pixel), %.1f GiB available",
                width, height, needed / kGiB, static_cast<int>(kPreviewBytesPerPixel), available_bytes / kGiB);
  throw Error(text);
}

// The memory check runs first, before any member allocates.
namespace {
// An adaptive frame traces up to kMaxPathsPerFrame paths per pixel: its shards of disjoint frames
// then keep disjoint sample indices (ProgressiveRenderer::set_sample_stride).
uint32_t sample_stride(const PreviewSettings& settings) { return settings.adaptive ? kMaxPathsPerFrame : 1u; }
}  // namespace

Preview::Preview(const Scene& scene, const PreviewSettings& settings, int width, int height)
    : width_((check_preview_memory(width, height, available_memory_bytes()), width)),
      height_(height),
      settings_(settings),
      renderer_(std::make_unique<ProgressiveRenderer>(scene, settings.trace, width, height)),
      inputs_(width, height),
      range_(width, height),
      filter_(width, height),
      blend_(width, height),
      tonemap_(width, height),
      hv_packed_(static_cast<size_t>(width) * height * 4) {
  range_.set_settings(settings_.range);
  range_.set_scene(scene);
  range_.set_camera(renderer_->camera());
  renderer_->set_sample_stride(sample_stride(settings_));
  prepare_filter();
}

Preview::~Preview() = default;

// Outside any timed run: on llvmpipe the first à-trous run with demodulation measured 52 ms
// against 22 ms for the next ones, and the schedule and --time's reserve predict from it.
void Preview::prepare_filter() {
  if (!settings_.filtering()) return;
  filter_.prepare(settings_.filter.kind);
  if (settings_.demodulate && !demod_) demod_ = std::make_unique<Demodulation>(width_, height_);
}

void Preview::reset() {
  restart_samples();
  if (history_) history_->drop();
}

void Preview::restart_samples() {
  renderer_->reset();
  pending_.clear();
  open_run_ = OpenFilterRun{};
  combined_now_ = false;
  // The newest run's cost stays a valid prediction (same size): the share bound then also holds
  // right after a camera change.
  const double last_run_ms = schedule_.last_run_ms;
  schedule_ = ScheduleState{};
  schedule_.last_run_ms = last_run_ms;
  have_filtered_ = false;
  uploaded_ = false;
  filtered_samples_ = -1;
  case_counts_ = {};
  next_active_.clear();
  first_frame_extra_paths_ = false;
  active_credit_.clear();
  rates_.clear();
  replans_ = replan_schedule(0);
}

GrowingSchedule Preview::replan_schedule(int frames_done) const {
  const AdaptiveParams& params = settings_.adaptive_params;
  return GrowingSchedule(static_cast<int>(params.warmup_frames), params.replan_divisor, frames_done);
}

void Preview::set_first_frame(uint32_t first) {
  renderer_->set_first_frame(first);
  reset();
}

void Preview::load_accumulation(const Accumulation& acc, uint32_t first, int frames) {
  reset();
  renderer_->restore(acc, first, frames);
  update_hv_empty();
}

void Preview::load_state(const AccumulationState& state) {
  reset();
  renderer_->restore(state.acc, state.frames.front().begin, static_cast<int>(state.frame_count()), state.traced,
                     state.guiding_field, state.environment_visibility);
  update_hv_empty();
  if (!state.settings.adaptive) return;
  replans_ = replan_schedule(samples());
  if (std::any_of(state.rate.begin(), state.rate.end(), [](float r) { return r > 0.0f; })) rates_ = state.rate;
  active_credit_ = state.credit;
  // One path for every pixel is the uniform frame (the same paths).
  const bool uniform = std::all_of(state.next_active.begin(), state.next_active.end(), [](uint8_t a) { return a == 1; });
  if (!uniform) next_active_ = state.next_active;
}

void Preview::set_camera(const Camera& camera) {
  begin_camera_change(camera);
  while (passes_pending()) run_next_pass();
}

void Preview::begin_camera_change(const Camera& camera) {
  if (settings_.motion_history) keep_history();
  renderer_->set_camera(camera);
  range_.set_camera(camera);
  restart_samples();
  if (!settings_.motion_history) {
    if (history_) history_->drop();
    return;
  }
  if (history_ && history_->has_kept()) pending_ = {PassStep::ViewRange, PassStep::Reproject};
}

bool Preview::history_active() const { return history_ && history_->active(static_cast<float>(samples())); }

// What the view shows now: its samples (with the history they were combined with), or, when the
// frame in flight was cancelled, the last combination, which is still this view's. Nothing new to
// keep leaves the view kept before it, which then reprojects into the new camera.
void Preview::keep_history() {
  if (samples() == 0 && !(history_ && history_->has_combination())) return;
  if (!history_) history_ = std::make_unique<HistoryPass>(width_, height_);
  if (range_.frames() == 0) step_range_buffer();
  if (samples() > 0) upload();
  history_->keep(inputs_, static_cast<float>(samples()), range_.guide(), range_.frame_color(), renderer_->camera());
}

// After the new view's first range frame (PassStep::ViewRange, its distances).
void Preview::reproject_history() {
  if (!history_ || !history_->has_kept()) return;  // dropped since the step was queued
  const auto start = BenchClock::now();
  history_->reproject(range_.guide(), range_.frame_color(), renderer_->camera());
  plan_first_frame_after_move();
  reproject_ms_ = elapsed_ms(start);
  last_.range += reproject_ms_;
}

// A pixel that traced extra paths in the view's first frame passes its mean with its variance
// unknown, as a one-path pixel does. Its own variance from 4 paths, pooled over a neighbourhood that
// the range weights cut (a crease: its taps straddle two normals, so it took no history), was often
// too low: the blend showed it partly unfiltered, coloured specks along a room's creases while the
// camera moved (docs/measurements.md, "A moving camera"). Unknown, it shows the filtered value, and
// the filter gets its 4-path mean.
void Preview::hide_first_frame_variances() {
  const std::vector<uint32_t>& paths = renderer_->pixel_frames();
  for (size_t p = 0; p < paths.size(); ++p)
    if (paths[p] > 1) hv_packed_[4 * p + 3] = kVarUnknown;
}

// The pixels whose history holds fewer than shared::kHistoryFirstFrameSamples samples trace the
// difference in the first frame (shared::first_frame_paths); the others one path, as always. The
// extra paths are at most kFirstFrameExtraShare of a uniform frame's: where a move uncovers much of
// the image (a fast turn), each uncovered pixel's extra paths are scaled down, to none when more
// than that share of the image is new, so that the new view comes no later than about 1.5 frames'
// tracing (without the bound, a fast turn in the explorer traced far more than that in one frame).
void Preview::plan_first_frame_after_move() {
  const Image history = history_->history_lv_image();  // alpha: the samples it holds
  std::vector<uint8_t> paths(static_cast<size_t>(width_) * height_, 1);
  uint64_t extra = 0;
  for (size_t p = 0; p < paths.size(); ++p) {
    paths[p] = static_cast<uint8_t>(shared::first_frame_paths(history.pixels[4 * p + 3]));
    extra += paths[p] - 1u;
  }
  if (extra == 0) return;
  const double bound = kFirstFrameExtraShare * static_cast<double>(paths.size());
  if (static_cast<double>(extra) > bound) {
    const double scale = bound / static_cast<double>(extra);
    for (uint8_t& n : paths) n = static_cast<uint8_t>(1 + static_cast<int>(std::floor((n - 1) * scale)));
  }
  next_active_ = std::move(paths);
  if (std::all_of(next_active_.begin(), next_active_.end(), [](uint8_t n) { return n == 1; })) next_active_.clear();
  first_frame_extra_paths_ = !next_active_.empty();
}

void Preview::set_settings(const PreviewSettings& settings) {
  // What the change invalidates: each setting's descriptor says (preview/setting_table.h).
  const bool retrace = changes(settings_, settings, SettingEffect::Retrace) || changes(settings_, settings, SettingEffect::Restart);
  const bool refilter = changes(settings_, settings, SettingEffect::Refilter) ||
                        !same_internal_filter_params(settings.filter, settings_.filter);
  settings_ = settings;
  range_.set_settings(settings_.range);
  renderer_->set_sample_stride(sample_stride(settings_));
  if (!settings_.motion_history && history_) history_->drop();
  prepare_filter();
  if (retrace) {
    renderer_->set_params(settings_.trace);
    reset();
    return;
  }
  if (refilter) {
    // The samples stay valid: filter them again with the new parameters (or drop L_f).
    schedule_.all_pixels_case2 = false;
    have_filtered_ = false;
    if (settings_.filtering() && samples() > 0 && !schedule_.hv_empty) run_filter();
  }
  if (samples() > 0) redisplay();
}

void Preview::upload() {
  if (uploaded_) return;
  const auto start = BenchClock::now();
  const Accumulation& acc = renderer_->accumulation();
  static_assert(kVarUnknown == -1.0f, "Accumulation marks an unknown variance (n < 2) with -1");
  acc.hv_and_variance_of_mean(hv_packed_.data());
  if (samples() == 1 && first_frame_extra_paths_) hide_first_frame_variances();
  const std::vector<uint32_t>& paths = renderer_->pixel_frames();
  const uint32_t frames = static_cast<uint32_t>(samples());
  if (std::all_of(paths.begin(), paths.end(), [frames](uint32_t n) { return n == frames; })) {
    inputs_.upload_packed(&acc.lv_mean[0].x, hv_packed_.data());  // every factor 1
  } else {
    // Each pixel's threshold is t_{n_p}: its factor against the run's t_n (shared::pixel_threshold).
    const float t_now = threshold_now();
    lv_packed_.resize(paths.size() * 4);
    for (size_t p = 0; p < paths.size(); ++p) {
      for (int c = 0; c < 3; ++c) lv_packed_[4 * p + c] = acc.lv_mean[p][c];
      lv_packed_[4 * p + 3] = t_now > 0.0f ? effective_threshold(settings_.threshold, paths[p]) / t_now : 1.0f;
    }
    inputs_.upload_packed_with_threshold(lv_packed_.data(), hv_packed_.data());
  }
  combined_now_ = history_active();
  if (combined_now_) history_->combine(inputs_, static_cast<float>(samples()));
  last_.upload += elapsed_ms(start);
  uploaded_ = true;
  upload_halves();
}

// The halves exist for the accumulation alone: a view that adds the reprojected history blends with
// one decision.
void Preview::upload_halves() {
  if (!settings_.trace.split_halves || combined_now_ || inputs_.has_halves()) return;
  const auto start = BenchClock::now();
  const size_t pixels = static_cast<size_t>(width_) * static_cast<size_t>(height_);
  halves_packed_.resize(4 * pixels);
  half_variances_packed_.resize(2 * pixels);
  renderer_->accumulation().hv_halves(hv_packed_.data(), halves_packed_.data(), half_variances_packed_.data());
  inputs_.upload_halves(halves_packed_.data(), half_variances_packed_.data());
  last_.upload += elapsed_ms(start);
}

bool Preview::step_range_buffer() {
  const auto start = BenchClock::now();
  const bool stepped = range_.step([this](const std::vector<uint32_t>& pixels, glm::vec2 jitter) {
    return renderer_->trace_specular_chains(pixels, jitter);
  });
  last_.range += elapsed_ms(start);
  return stepped;
}

void Preview::converge_range_buffer() {
  while (step_range_buffer()) {
  }
}

// The range buffer's antialiasing frames are spread over the path-tracing frames instead of all
// run before the first filter: the first filter run takes one range frame, and each later frame
// adds one more only while filter + range stay within kPassShare of the tracing time. A camera
// change so costs one range frame up front, and the guide sharpens as the budget allows.
void Preview::advance_range_buffer() {
  if (!range_due()) return;
  const double before = last_.range;
  step_range_buffer();
  schedule_.pass_ms += last_.range - before;
}

// u / t of every pixel whose perceived HV noise is above the threshold it is blended at
// (noise_sigma_s). The blend's background L_f + L_lv is not known before the filter has run; L_u
// + L_lv, its unfiltered counterpart, stands for it.
std::vector<float> Preview::noise_over_threshold() const {
  const Accumulation& acc = renderer_->accumulation();
  std::vector<float> needed;
  for (size_t p = 0; p < acc.samples.size(); ++p) {
    const double variance = acc.variance_of_mean(p), t = effective_threshold(settings_.threshold, acc.samples[p]);
    const glm::vec3 hv = acc.hv_mean[p], lv = acc.lv_mean[p];
    const double background = luminance(hv.x, hv.y, hv.z) + luminance(lv.x, lv.y, lv.z);
    if (!(variance > 0.0) || !(background > 0.0) || !(t > 0.0)) continue;
    const double ratio = variance / background / background / t;
    if (ratio > 1.0) needed.push_back(static_cast<float>(std::min(ratio, 1e30)));
  }
  return needed;
}

FilterParams Preview::filter_params_now() const {
  FilterParams p = settings_.filter;
  p.split = settings_.trace.split_halves;
  if (settings_.shrink_sigma) {
    std::vector<float> needed = noise_over_threshold();
    p.sigma_s = noise_sigma_s(p.sigma_s, static_cast<uint64_t>(samples()), needed);
  }
  return p;
}

// A run in parts keeps its arguments (the inputs, the guide) in place until its last step: the
// passes that may run between two steps (the explorer's views) only read them, and whatever changes
// them (a traced frame, a camera change, a reset) first abandons the run (open_run_ cleared).
void Preview::run_filter() {
  begin_filter_run();
  while (!step_filter_run()) {
  }
}

void Preview::begin_filter_run() {
  const auto start = BenchClock::now();
  const double range_before = last_.range;
  const FilterParams params = filter_params_now();
  if (range_.frames() == 0) step_range_buffer();
  upload();
  open_run_ = OpenFilterRun{true, settings_.demodulate};
  if (settings_.demodulate) {
    const auto demod_start = BenchClock::now();
    if (!demod_) demod_ = std::make_unique<Demodulation>(width_, height_);
    PreviewInputs& in = pass_inputs();
    in.upload_albedo(&renderer_->accumulation().albedo_mean[0].x);
    demod_->demodulate(in, range_.guide(), params, threshold_now(), &range_.surface());
    filter_.begin(demod_->filter_inputs(), range_.guide(), params, threshold_now(), &range_.surface());
    open_run_.filter_ms = elapsed_ms(demod_start);
  } else {
    filter_.begin(inputs(), range_.guide(), params, threshold_now(), &range_.surface());
  }
  open_run_.range_ms = last_.range - range_before;
  last_sigma_s_ = params.sigma_s;
  record_filter_part_ms(elapsed_ms(start));
}

void Preview::record_filter_part_ms(double ms) {
  const size_t part = open_run_.parts_done++;
  if (filter_part_ms_.size() <= part) filter_part_ms_.resize(part + 1, 0.0);
  filter_part_ms_[part] = ms;
}

bool Preview::step_filter_run() {
  const auto start = BenchClock::now();
  const bool done = filter_.step();
  if (done && open_run_.demodulated) demod_->remodulate(filter_.output(), pass_inputs());
  if (open_run_.demodulated) open_run_.filter_ms += elapsed_ms(start);
  // The read-back ends the run's GL work: a step that only submits it (the slice, a draw, with
  // GlTiming::Submit) is paid for here, within the last part's time.
  const uint32_t filtered_pixels = done ? filter_.filtered_pixels() : 0;
  record_filter_part_ms(elapsed_ms(start));
  if (!done) return false;
  // The run's cost as the schedule and the stage times count it: the filter's own stage timer
  // (gl_timing()), or, demodulated, the wall time of the demodulation, the filter and the
  // remodulation.
  if (!open_run_.demodulated) open_run_.filter_ms = filter_.last_ms();
  last_.filter += open_run_.filter_ms;
  filtered_demodulated_ = open_run_.demodulated;
  schedule_.last_run_ms = open_run_.filter_ms;
  schedule_.pass_ms += open_run_.filter_ms + open_run_.range_ms;
  open_run_ = OpenFilterRun{};
  ++filter_runs_;
  filtered_samples_ = samples();
  have_filtered_ = true;
  // Every pixel skipped = every pixel already in case 2: the filter is not needed any more.
  if (settings_.filter.skip_case2 && filtered_pixels == 0) schedule_.all_pixels_case2 = true;
  return true;
}

void Preview::run_filter_step() {
  if (!open_run_.open) {
    if (!filter_due_now() || !filter_worthwhile()) return;
    begin_filter_run();
  } else if (step_filter_run()) {
    return;
  }
  pending_.push_front(PassStep::Filter);  // more of the run to come
}

double Preview::case2_share() const {
  const double pixels = static_cast<double>(width_) * static_cast<double>(height_);
  return pixels > 0 ? case_counts_[kCaseUnfiltered] / pixels : 0.0;
}

bool Preview::filter_needed() const { return hv_energy_share(renderer_->accumulation()) >= kMinHvShare; }

bool Preview::clean() const { return case2_share() == 1.0 || (!have_filtered_ && !filter_needed()); }

bool Preview::filter_worthwhile() {
  if (filter_needed()) return true;
  ++low_hv_skips_;
  return false;
}

const Texture2D& Preview::filtered_output() const {
  return filtered_demodulated_ && demod_ ? demod_->output() : filter_.output();
}

Image Preview::filtered_image() const {
  return filtered_demodulated_ && demod_ ? demod_->filtered_image() : filter_.filtered_image();
}

Image Preview::filtered_variance_image() const {
  return filtered_demodulated_ && demod_ ? demod_->variance_image() : filter_.variance_image();
}

void Preview::update_hv_empty() {
  if (!schedule_.hv_empty) return;  // once there is HV light it stays
  for (const glm::vec3& v : renderer_->accumulation().hv_mean)
    if (v.x != 0.0f || v.y != 0.0f || v.z != 0.0f) {
      schedule_.hv_empty = false;
      return;
    }
}

void Preview::blend_and_tonemap() {
  const double upload_before = last_.upload;
  upload();
  // The filter's centre weight is that of the demodulated run too: with a grey factor a,
  // Cov[L_u, a L_f'] = a w Var[L_u] / a = w Var[L_u], the blend's covariance term is unchanged.
  // Once a filter run skipped every pixel, its L_f marks every pixel case 2 and the guard, which
  // acts in cases 1 and 3 only, would change nothing: its passes are left out (the same image).
  const bool guard = settings_.bias_guard && !schedule_.all_pixels_case2;
  blend_.run(inputs(), have_filtered_ ? &filtered_output() : nullptr, &range_.guide(), threshold_now(),
             BlendParams{range_weights(settings_.filter), guard, static_cast<float>(samples()),
                         settings_.trace.split_halves},
             have_filtered_ ? filter_.centre_weight() : nullptr,
             &range_.surface());
  last_.blend += blend_.last_ms();
  tonemap_.run(blend_.output(), settings_.tonemap);
  last_.tonemap += tonemap_.last_ms();
  case_counts_ = shown_case_counts_ = blend_.case_counts();
  display_ms_ = last_.upload - upload_before + blend_.last_ms() + tonemap_.last_ms();
}

void Preview::redisplay() { blend_and_tonemap(); }

void Preview::add_frame(bool last_frame, bool display) {
  trace_frame();
  queue_passes(last_frame, display);
  while (passes_pending()) run_next_pass();
}

bool Preview::trace_frame() {
  pending_.clear();
  open_run_ = OpenFilterRun{};
  last_ = StageTimes{};
  const auto start = BenchClock::now();
  const bool complete = next_active_.empty() ? renderer_->add_frame() : renderer_->add_frame(next_active_);
  last_.path_tracing = elapsed_ms(start);
  uploaded_ = false;
  if (!complete) return false;  // cancelled: the renderer reset its samples; the caller resets too
  schedule_.tracing_ms += last_.path_tracing;
  constexpr size_t kRecentFrames = 8;
  if (recent_frame_ms_.size() == kRecentFrames) recent_frame_ms_.erase(recent_frame_ms_.begin());
  recent_frame_ms_.push_back(last_.path_tracing);
  total_.path_tracing += last_.path_tracing;
  return true;
}

bool Preview::allocating() const {
  return settings_.adaptive && static_cast<uint32_t>(samples()) >= settings_.adaptive_params.warmup_frames;
}

std::vector<float> Preview::allocation_rates() {
  const Accumulation& acc = renderer_->accumulation();
  const int w = width_, h = height_;
  Image lv = Image::rgb(w, h), hv = Image::rgb(w, h), var_lv = Image::gray(w, h);
  for (size_t p = 0; p < acc.samples.size(); ++p) {
    for (int c = 0; c < 3; ++c) {
      lv.pixels[3 * p + c] = acc.lv_mean[p][c];
      hv.pixels[3 * p + c] = acc.hv_mean[p][c];
    }
    // Case 2, the clean goal's aim, reads Var[L_u] alone: there Var[L_lv] is left at 0.
    if (settings_.adaptive_params.goal == AdaptiveGoal::Error) var_lv.pixels[p] = acc.lv_variance_of_mean(p);
  }
  Image var_u = Image::gray(w, h);
  acc.variance_of_mean_image(var_u.pixels.data(), 1);
  const std::vector<uint32_t>& paths = renderer_->pixel_frames();
  const std::vector<float> need = final_pixel_need(lv, hv, var_u, var_lv, paths, settings_.threshold);
  return pxf::allocation_rates(need, paths, w, h, settings_.adaptive_params);
}

void Preview::plan_next_frame() {
  next_active_.clear();
  if (!allocating()) return;
  if (replans_.due(samples()) || rates_.empty()) {
    rates_ = allocation_rates();
    replans_.done(samples());
  }
  const std::vector<float>& rates = rates_;
  // A frame that would trace nothing is no frame: the credits move on until some pixel is due (at
  // most 1 / floor_rate steps, when every pixel is at the floor).
  do {
    next_active_ = select_active(rates, active_credit_);
  } while (std::all_of(next_active_.begin(), next_active_.end(), [](uint8_t paths) { return paths == 0; }));
}

void Preview::queue_passes(bool last_frame, bool display) {
  update_hv_empty();
  schedule_.history_active = history_active();
  plan_next_frame();
  pending_last_frame_ = last_frame;
  pending_ = {PassStep::RangeFrame, PassStep::Filter};
  if (last_frame || display) pending_.push_back(PassStep::Display);
}

double Preview::predict_pass_ms(PassStep step) const {
  switch (step) {
    case PassStep::RangeFrame:
      return range_due() ? range_.last_ms() : 0.0;
    case PassStep::Filter:
      if (!open_run_.open && !filter_due_now()) return 0.0;
      return open_run_.parts_done < filter_part_ms_.size() ? filter_part_ms_[open_run_.parts_done] : 0.0;
    case PassStep::Display:
      return display_ms_;
    case PassStep::ViewRange:
      return range_.last_ms();
    case PassStep::Reproject:
      return reproject_ms_;
  }
  return 0.0;
}

void Preview::run_next_pass() {
  if (pending_.empty()) return;
  const PassStep step = pending_.front();
  pending_.pop_front();
  const StageTimes before = last_;
  switch (step) {
    case PassStep::RangeFrame:
      advance_range_buffer();
      schedule_.have_filtered = have_filtered_;
      break;
    case PassStep::Filter:
      run_filter_step();
      break;
    case PassStep::Display:
      blend_and_tonemap();
      break;
    case PassStep::ViewRange:
      step_range_buffer();
      break;
    case PassStep::Reproject:
      reproject_history();
      break;
  }
  total_ += last_ - before;  // what this step added (its path tracing is 0)
}

// The last frame always filters: its run (predicted by the newest one) is kept in reserve, so that
// the range frames never push a job's passes past kPassShare once that run comes.
bool Preview::range_due() const {
  return settings_.filtering() && !schedule_.hv_empty && range_.frames() != 0 && !range_.converged() &&
         schedule_.pass_ms + range_.last_ms() + schedule_.last_run_ms <= kPassShare * schedule_.tracing_ms;
}

bool Preview::filter_due_now() const {
  if (!settings_.filtering()) return false;
  if (pending_last_frame_)
    return filtered_samples_ != samples() && filter_due(settings_.schedule, samples(), true, schedule_now());
  return filter_due(settings_.schedule, samples(), false, schedule_now());
}

void Preview::finish_passes() {
  if (settings_.filtering() && filtered_samples_ != samples() &&
      filter_due(settings_.schedule, samples(), true, schedule_now()) && filter_worthwhile())
    run_filter();
  blend_and_tonemap();
}

ScheduleState Preview::schedule_now() const {
  ScheduleState s = schedule_;
  s.first_range_ms = range_.frames() == 0 ? range_.last_ms() : 0.0;
  return s;
}

TimeBudget Preview::predict_next_frame(double budget_ms, double elapsed_ms) const {
  MeasuredJob job;
  job.schedule = settings_.schedule;
  job.filtering = settings_.filtering();
  job.samples = samples();
  job.state = schedule_now();
  job.recent_frame_ms = recent_frame_ms_;
  job.display_ms = display_ms_;
  return pxf::predict_next_frame(job, budget_ms, elapsed_ms);
}

void Preview::finish() {
  last_ = StageTimes{};
  finish_passes();
  total_ += last_;
}

Image Preview::display_image() const { return tonemap_.display_image(); }
Image Preview::final_image() const { return blend_.final_image(); }

std::vector<Layer> Preview::buffers() {
  if (range_.frames() == 0) converge_range_buffer();  // else the guide the filter and blend used
  upload();
  std::vector<Layer> layers;
  layers.push_back({"final", blend_.final_image()});
  // The inputs as the renderer holds them (the textures hold the same floats), not read back.
  layers.push_back({"lv", renderer_->lv_image()});
  layers.push_back({"hv", renderer_->hv_image()});
  layers.push_back({"hv_filtered", have_filtered_ ? filtered_image() : renderer_->hv_image()});
  Image var_u = Image::gray(width_, height_);  // Var[L_u] as uploaded, 0 where unknown
  for (size_t i = 0; i < var_u.pixels.size(); ++i) var_u.pixels[i] = std::max(0.0f, hv_packed_[4 * i + 3]);
  layers.push_back({"var_u", std::move(var_u)});
  layers.push_back({"var_f", have_filtered_ ? filtered_variance_image() : Image::gray(width_, height_)});
  layers.push_back({"blend", blend_.s_image()});
  layers.push_back({"case", blend_.case_image()});
  layers.push_back({"range_color", range_.range_color_image()});
  layers.push_back({"depth", range_.depth_image()});
  layers.push_back({"samples", renderer_->samples_image()});
  layers.push_back({"emitter", renderer_->emitter_coverage_image()});
  layers.push_back({"albedo", renderer_->albedo_image()});
  return layers;
}

}  // namespace pxf
