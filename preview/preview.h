// The preview core shared by `pxf render`, `pxf explore` and `pxf bench`: the progressive path
// tracer plus the GL passes (range, filter, blend, tone map) on the schedule of docs/method.md section 4.
// Requires a current GL context (gl/context.h) for its whole life.
// Usage:
//   Preview preview(scene, settings, w, h);
//   for (int i = 0; i < spp; ++i) preview.add_frame(/*last_frame=*/i + 1 == spp, /*display=*/...);
//   preview.display_image(); preview.buffers();   // tone-mapped image; every buffer as EXR layers
#pragma once
#include <array>
#include <deque>
#include <memory>
#include <string>
#include <vector>

#include "gl/blend_pass.h"
#include "gl/demodulation.h"
#include "gl/filter_pass.h"
#include "gl/history_pass.h"
#include "gl/inputs.h"
#include "gl/pass_params.h"
#include "gl/range_pass.h"
#include "gl/tonemap_pass.h"
#include "image/image.h"
#include "pathtracer/accumulation_state.h"
#include "pathtracer/pathtracer.h"
#include "preview/adaptive.h"
#include "preview/frame_budget.h"
#include "preview/schedule.h"

namespace pxf {

// Every setting of a preview, held once: the command line (app/options.cpp) binds these fields
// directly, the explorer edits them, stats.json and the bench read them.
struct PreviewSettings {
  TraceParams trace;
  // t: allowed perceived (relative) variance. The one threshold: the filter's case-2 skip and the
  // blend both get it, scaled for the sample count by threshold_now() on every run.
  float threshold = 0.001f;
  FilterParams filter;  // variant (FilterKind::None = plain path tracing) and sigmas
  // Albedo demodulation: filter HV divided by the first non-delta vertex's directional albedo and
  // multiply L_f back (gl/demodulation.h), so the filter smooths illumination, not texture, and thin
  // strands keep their gaps.
  bool demodulate = true;
  // The blend's bias guard (BlendParams::bias_guard, docs/method.md section 3.7): s raised where
  // L_f measurably differs from L_u. On: at equal time it lowered the filtered image's error on all
  // four built-in scenes (docs/measurements.md, "Bias guard"); off is the method's blend as published.
  bool bias_guard = true;
  // Shrink the filter's sigma_s to the noise (noise_sigma_s in gl/pass_params.h, docs/method.md
  // 2.5): the kernel the noisiest pixels need to reach t, between 2 px and filter.sigma_s. On by
  // default: less bias where samples have accumulated, the full kernel where the noise needs it;
  // off keeps filter.sigma_s for every run, as the method was published.
  bool shrink_sigma = true;
  // Adaptive sampling (preview/adaptive.h): after adaptive_params.warmup_frames uniform
  // frames, each frame traces only the pixels the allocation picks, each at its own sample index.
  // Off by default until pxf bench shows it wins.
  bool adaptive = false;
  AdaptiveParams adaptive_params;
  FilterSchedule schedule = FilterSchedule::Final;  // headless jobs; the explorer's is Budget
  TonemapParams tonemap;
  RangeSettings range;
  // Reprojected history (docs/method.md section 4.1): a camera move keeps what the view showed and
  // reprojects it into the new view, beside the fresh samples, with a weight that falls to 0 after
  // kHistoryFadeSamples samples. Acts only on a camera change after traced samples (the explorer,
  // camera paths); a render that never moves is unchanged.
  bool motion_history = true;
  bool filtering() const { return filter.kind != FilterKind::None; }
};

// The name table of FilterKind for the command line and the UI (index = value): the GL variants
// (filter_kind_names()) and "none" (FilterKind::None).
const std::vector<std::string>& filter_option_names();

// Milliseconds per stage (reported in stats.json and by pxf bench).
struct StageTimes {
  double path_tracing = 0, upload = 0, range = 0, filter = 0, blend = 0, tonemap = 0;
  double total() const { return path_tracing + upload + range + filter + blend + tonemap; }
  StageTimes& operator+=(const StageTimes& o);
  StageTimes operator-(const StageTimes& o) const;
};

// Share of a job's wall time spent outside path tracing.
double share_outside_tracing(const StageTimes& t, double wall_ms);
// Filter + range time as a share of the path-tracing time (the budget schedule's bound).
double pass_share_of_tracing(const StageTimes& t);

// HV's share of the image's energy: sum of Y(L_u) over sum of Y(L_u) + Y(L_lv), 0 for a black
// image. Below kMinHvShare the filter does not run: HV then carries too little of the image for
// its noise to matter next to LV's, and a run would cost time for no visible change.
double hv_energy_share(const Accumulation& acc);
constexpr double kMinHvShare = 0.01;

// The extra paths of the first frame after a camera move (Preview::plan_first_frame_after_move)
// are at most this share of a uniform frame's paths.
constexpr double kFirstFrameExtraShare = 0.5;

// Memory a Preview of width x height needs, checked before it allocates anything: the peak memory
// of `pxf render` grows by about this much per pixel (the slope between two image sizes, plus what
// each pass's textures added since; docs/notebook/measurements.md has the figures): the
// accumulation (means, variances in double, albedo, replicates), the GL textures of every pass, and
// the read-backs written to buffers.exr.
constexpr uint64_t kPreviewBytesPerPixel = 770;
uint64_t preview_bytes(int width, int height);
// Throws pxf::Error, one line naming the size and both figures, when preview_bytes exceeds
// `available_bytes` (available_memory_bytes() in the constructor).
void check_preview_memory(int width, int height, uint64_t available_bytes);

class Preview {
 public:
  // `scene` is referenced, not copied (ProgressiveRenderer): it must outlive the Preview.
  Preview(const Scene& scene, const PreviewSettings& settings, int width, int height);
  Preview(Scene&& scene, const PreviewSettings& settings, int width, int height) = delete;
  ~Preview();

  // Traces one path per pixel, then runs the passes that are due. `display`: also blend and tone
  // map (the explorer displays every frame; a headless render only its last one).
  void add_frame(bool last_frame = false, bool display = true);
  // add_frame in steps, for the explorer, which traces on a worker thread and spreads the GL passes
  // over display frames (preview/frame_budget.h): trace_frame() touches only the path tracer (safe on
  // another thread while nothing else uses this Preview; returns false if cancel_trace() stopped
  // it, and the samples are then reset), queue_passes() queues what add_frame would run after it,
  // run_next_pass() runs one queued step on the GL thread. add_frame is exactly these in sequence.
  bool trace_frame();
  void queue_passes(bool last_frame, bool display);
  bool passes_pending() const { return !pending_.empty(); }
  PassStep next_pass() const { return pending_.front(); }
  double predict_pass_ms(PassStep step) const;  // 0 when the step would do nothing now
  void run_next_pass();
  void cancel_trace() { renderer_->cancel_frame(); }  // thread-safe
  // Ends a capture (also an interrupted one): the last-frame filter run if due, blend, tone map.
  void finish();
  // Changes settings. Path-tracing changes reset the accumulation; filter, threshold and display
  // changes apply at once to the current samples (re-filtering if a filtered image exists).
  void set_settings(const PreviewSettings& settings);
  void set_camera(const Camera& camera);  // resets; begin_camera_change and its steps, all at once
  // A camera change whose GL work is spread over display frames (the explorer): keeps the view for
  // the history and resets at once, then queues the new view's range frame and the reprojection
  // (PassStep::ViewRange, PassStep::Reproject) when there is a history to reproject. They must run
  // (run_next_pass) before the next trace_frame, which plans with their result.
  void begin_camera_change(const Camera& camera);
  void reset();
  // Starts the frame sequence at `first` (a shard of frames first:B); resets.
  void set_first_frame(uint32_t first);
  // Replaces the samples by a saved accumulation of the frames [first, first + frames) (resume,
  // merge); the passes then run on it as on traced frames.
  void load_accumulation(const Accumulation& acc, uint32_t first, int frames);
  // The same from a state (resume, merge) with its per-pixel traced counts; an adaptive state's
  // allocation (credits and the planned mask) too, so that the next frame is the one the
  // interrupted render would have traced. The state's frames must be one range.
  void load_state(const AccumulationState& state);
  // Blend and tone map the current state (e.g. after a display-only change).
  void redisplay();
  // Runs the range pass until it has converged (the explorer's range views need it unfiltered too).
  void converge_range_buffer();

  int width() const { return width_; }
  int height() const { return height_; }
  int samples() const { return renderer_->frames(); }  // frames traced; a pixel's own count: pixel_samples()
  const std::vector<uint32_t>& pixel_samples() const { return renderer_->pixel_frames(); }
  // Adaptive sampling's allocation: the next frame's path count per pixel (empty = one in every pixel) and the
  // per-pixel credits it was selected with (empty before the first allocation; preview/adaptive.h).
  const std::vector<uint8_t>& next_active() const { return next_active_; }
  const std::vector<float>& allocation_credit() const { return active_credit_; }
  const std::vector<float>& allocation_rates_now() const { return rates_; }  // empty before the first
  // The threshold the filter's skip and the blend get now: t scaled for the variance estimate's
  // own noise at this sample count (effective_threshold, docs/method.md section 3.5).
  float threshold_now() const { return effective_threshold(settings_.threshold, static_cast<uint64_t>(samples())); }
  const PreviewSettings& settings() const { return settings_; }
  const ProgressiveRenderer& renderer() const { return *renderer_; }
  const StageTimes& last_times() const { return last_; }
  const StageTimes& total_times() const { return total_; }
  int filter_runs() const { return filter_runs_; }
  // The filter's parameters for a run now: settings().filter with sigma_s shrunk to the noise
  // (noise_sigma_s) when settings().shrink_sigma.
  FilterParams filter_params_now() const;
  // The sigma_s of the last filter run (0 before the first).
  float last_sigma_s() const { return last_sigma_s_; }
  // The `--time` prediction for one more frame: its tracing, the passes it makes due, and the
  // finish after it (last filter run if due, upload, blend, tone map), from measured costs.
  TimeBudget predict_next_frame(double budget_ms, double elapsed_ms) const;
  bool filter_stopped() const { return schedule_.all_pixels_case2; }
  // The share of pixels in case 2 at the last blend (1 = clean: the unbiased image at threshold t).
  double case2_share() const;
  // Whether the filter has anything to do: HV's energy share reaches kMinHvShare (none below it,
  // no HV at all included). Computed from the accumulation now.
  bool filter_needed() const;
  // Clean: every pixel in case 2 at the last blend, or no filter run yet while none is needed, so
  // that every pixel shows its unfiltered, unbiased value.
  bool clean() const;
  // Filter runs left out because HV's energy share was below kMinHvShare.
  int filter_runs_skipped_low_hv() const { return low_hv_skips_; }
  // Pixels per blend case (kCase* in shaders/pass_formulas.h) of the last displayed frame.
  // 0 after a reset or a camera change, until the next blend.
  const std::array<uint32_t, kBlendCaseCount>& case_counts() const { return case_counts_; }
  // The same of the blend that display_image() and the views show: the last blend, also after a
  // reset or a camera change, until the next one (the explorer's status line and case legend).
  const std::array<uint32_t, kBlendCaseCount>& shown_case_counts() const { return shown_case_counts_; }

  // GPU results for the explorer's views.
  // The inputs the filter and blend read: the fresh samples, or with the reprojected history
  // beside them while it has weight (HistoryPass::combine).
  const PreviewInputs& inputs() const { return combined_now_ ? history_->combined() : inputs_; }
  // The reprojected history (nullptr before the first camera move with motion_history on).
  const HistoryPass* history() const { return history_.get(); }
  // Whether the history still has weight in the current samples.
  bool history_active() const;
  const RangePass& range() const { return range_; }
  const FilterPass& filter() const { return filter_; }
  const BlendPass& blend() const { return blend_; }
  const TonemapPass& tonemap() const { return tonemap_; }
  bool has_filtered() const { return have_filtered_; }
  // The newest L_f as the blend sees it (rgb L_f, a Var[L_f] or a sentinel): the filter's output,
  // remodulated when it was demodulated. Valid when has_filtered().
  const Texture2D& filtered_output() const;
  Image filtered_image() const;           // "R,G,B" L_f
  Image filtered_variance_image() const;  // "Y" Var[L_f], 0 where unknown or skipped

  Image display_image() const;        // tone-mapped sRGB "R,G,B" in [0,1]
  Image final_image() const;          // linear radiance after the blend
  // Every buffer as EXR layers: final, lv, hv, hv_filtered, var_u, var_f, blend, case,
  // range_color, depth, emitter, samples, albedo: the range layers are the guide the filter used (the range
  // pass runs to convergence only if it never ran).
  std::vector<Layer> buffers();

 private:
  ScheduleState schedule_now() const;  // schedule_ with the range frame the next run needs first
  std::vector<float> noise_over_threshold() const;  // filter_params_now's input
  void upload();
  void upload_halves();  // the split decision's halves, where it applies (after upload)
  PreviewInputs& pass_inputs() { return combined_now_ ? history_->combined() : inputs_; }
  // reset() without forgetting the history (a camera move keeps it).
  void restart_samples();
  // Keeps the current view for the history before the camera changes to `camera`, then reprojects.
  void keep_history();
  void reproject_history();
  void plan_first_frame_after_move();  // next_active_: more paths where the history holds few samples
  void hide_first_frame_variances();   // upload(): those pixels' Var[L_u] unknown in that frame
  // A filter run, whole (run_filter) or in parts that the queued Filter step runs one per call
  // (begin_filter_run, then step_filter_run until it returns true).
  void run_filter();
  void prepare_filter();  // the filter variant's programs (and the demodulation), before a run is timed
  void begin_filter_run();  // the range frame if none yet, the upload, the demodulation
  bool step_filter_run();   // the filter's next GL step; true after the last (then the bookkeeping)
  void run_filter_step();   // PassStep::Filter: begins a due run or steps the open one
  void record_filter_part_ms(double ms);  // the open run's next part took `ms`
  bool filter_worthwhile();  // HV's energy share reaches kMinHvShare (else counts a skip)
  bool step_range_buffer();     // one antialiasing frame of the range pass; false once converged
  void advance_range_buffer();  // one more range frame if the pass budget allows
  void update_hv_empty();
  void blend_and_tonemap();
  void finish_passes();
  bool range_due() const;       // one more range frame fits the pass budget
  // The next frame's active mask (adaptive sampling): empty = every pixel.
  void plan_next_frame();
  std::vector<float> allocation_rates();  // each pixel's paths per frame from the current samples
  GrowingSchedule replan_schedule(int frames_done) const;
  bool allocating() const;  // adaptive sampling is past its warm-up: frames follow plan_next_frame()
  // The range guide as images for the allocation's pooling, read back when the guide changed.
  bool filter_due_now() const;  // the queued Filter step would run the filter

  int width_, height_;
  PreviewSettings settings_;
  std::unique_ptr<ProgressiveRenderer> renderer_;
  PreviewInputs inputs_;
  RangePass range_;
  FilterPass filter_;
  std::unique_ptr<Demodulation> demod_;  // created on first use
  std::unique_ptr<HistoryPass> history_;  // created at the first camera move with motion_history
  bool combined_now_ = false;             // the passes read history_->combined() for the current samples
  bool filtered_demodulated_ = false;    // the newest L_f went through demod_
  BlendPass blend_;
  TonemapPass tonemap_;
  std::vector<float> hv_packed_;  // the HV texture's data (rgb L_u, a Var[L_u]), filled by the renderer
  std::vector<float> lv_packed_;  // the LV texture's data with per-pixel threshold factors (adaptive)
  std::vector<float> halves_packed_, half_variances_packed_;  // the split decision's (upload_halves)
  std::vector<uint8_t> next_active_;  // plan_next_frame()'s mask; empty = every pixel
  std::vector<float> active_credit_;  // select_active's credits
  std::vector<float> rates_;          // the last allocation's rates; empty before the first
  GrowingSchedule replans_{16, 16};   // when the rates are recomputed (replan_schedule)
  bool first_frame_extra_paths_ = false;  // plan_first_frame_after_move gave some pixels more paths
  ScheduleState schedule_;
  bool have_filtered_ = false;
  bool uploaded_ = false;  // inputs hold the current samples
  int filter_runs_ = 0;
  float last_sigma_s_ = 0.0f;
  int low_hv_skips_ = 0;
  int filtered_samples_ = -1;  // sample count of the newest L_f
  StageTimes last_, total_;
  std::array<uint32_t, kBlendCaseCount> case_counts_{};
  std::array<uint32_t, kBlendCaseCount> shown_case_counts_{};  // not reset: the shown image's
  std::vector<double> recent_frame_ms_;  // path tracing of the last frames, for predictions
  double display_ms_ = 0;                // upload + blend + tone map of the newest display
  double reproject_ms_ = 0;              // the newest reprojection with its path-count plan
  std::deque<PassStep> pending_;         // queue_passes() not yet run
  // The filter run begun and not finished (begin_filter_run): what it filters and what it cost.
  struct OpenFilterRun {
    bool open = false;
    bool demodulated = false;
    double filter_ms = 0, range_ms = 0;
    size_t parts_done = 0;  // begin_filter_run, then each step_filter_run
  } open_run_;
  // ms of each part of the newest run that reached it, as the Filter step's prediction: measured
  // here, around the part, since a GL step that only submits its work (the grid's slice, a draw)
  // is paid for at the next read-back.
  std::vector<double> filter_part_ms_;
  bool pending_last_frame_ = false;
};

}  // namespace pxf
