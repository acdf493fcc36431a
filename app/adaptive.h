// Adaptive sampling (issue 33): which pixels the next frame traces, from the method's own quantities.
// Pure functions on images and per-pixel counts, so that they are tested under a fake variance
// image (app/adaptive_test.cpp); the preview (app/preview.cpp) feeds them the accumulation.
//
// The rule, per frame after a uniform warm-up:
//   need r_p = q_p / t_{n_p}: the perceived variance of the FINAL unfiltered pixel L_lv + L_u,
//     q_p = (Var[L_u] + Var[L_lv]) / L_b^2 with L_b = Y(L_u) + Y(L_lv) as the filter's case-2 skip
//     takes it, against the threshold the blend gives that pixel, t (n_p - 3) / (n_p - 1).
//     r_p <= 1: the pixel is clean (case 2) by its own samples.
//   neighbourhood: each pixel is allocated by the largest need among the OTHER pixels of the box of
//     radius dilation_radius around it (Cycles dilates its active mask with a box), never by its
//     own. A pixel's rate decided by its own samples biases its mean: the pixel that drew a bright
//     path is traced more and the path diluted, the one that drew a dark run is retired and stays
//     dark (measured: cornell 48x48, 64 frames, 32 seeds, block means 1.5-3.5 % low, |z| up to 6.5
//     against an 8192-spp reference; tests/consistency_test.cpp). Decided by its neighbours, whose
//     samples are independent of its own, its count says nothing about its values. A caustic covers
//     more than one pixel, so its pixels keep each other sampled, and its quiet neighbours that
//     have not yet met its paths are sampled with it (the blend pools over neighbours for the same
//     reason).
//   minimum: a pixel with fewer than min_samples paths counts as at least at the threshold (r >= 1),
//     so that a pixel that only looks quiet (its rare bright paths not yet found) is not retired.
//   rate a_p = clamp(r_p / c, floor_rate, 1): paths per frame, c = full_rate_need, or the need at the
//     top full_rate_share of the pixels where that is larger. Samples follow u / t up to one path
//     per frame (a frame traces a pixel at most once); every pixel, clean or not, is revisited at
//     least every 1 / floor_rate frames.
//   selection: a per-pixel credit adds a_p each frame and the pixel is traced when it reaches 1
//     (error diffusion in time): deterministic, exactly a_p on average, no random numbers.
#pragma once
#include <cstdint>
#include <limits>
#include <vector>

#include "image/image.h"

namespace pxf {

struct AdaptiveParams {
  // Uniform frames before the first allocation. 16: below it the per-pixel variances that rank the
  // pixels rest on too few samples (the threshold correction (n - 3) / (n - 1) is 0.87 at 16), and
  // 16 = 2^4 uniform frames give every pixel a complete (0, 4, 2)-net prefix of its Sobol sequence.
  uint32_t warmup_frames = 16;
  // A pixel with fewer paths is never retired to the floor: its need counts as at least 1.
  uint32_t min_samples = 64;
  // The least rate of any pixel: every pixel is traced at least every 16 frames.
  float floor_rate = 1.0f / 16.0f;
  // The need at which a pixel is traced every frame; below it the rate is need / full_rate_need.
  float full_rate_need = 4.0f;
  // ... raised, where more than this share of the pixels is past it, to the need of the pixel at
  // that share (the neediest full_rate_share of the pixels are traced every frame, the others in
  // proportion). While most pixels are far from t, a fixed scale would trace nearly all of them every
  // frame, which is uniform sampling; this keeps a frame's paths on the neediest pixels. 0: off.
  float full_rate_share = 0.25f;
  // Radius of the box whose other pixels decide a pixel's rate (2: the 5x5 window of the bias guard).
  int dilation_radius = 2;
  // The rates are recomputed after the warm-up and then whenever the frames grew by 1/16 (at least
  // one frame): a pixel's variance estimate moves by a few per cent in 1/16 more samples, and the
  // per-frame CPU work on the GL thread stays a fraction of a path-tracing frame. Cycles likewise
  // updates its adaptive mask every few samples.
  int replan_divisor = 16;
};

// r_p of every pixel (row-major): lv, hv "R,G,B" means; var_u, var_lv "Y" variances of the means
// (negative = unknown, n < 2); paths[p] the pixel's count n_p; t the threshold (--threshold). An
// unknown variance gives +inf (the pixel must be sampled); V = 0 (all samples equal) gives 0, which
// min_samples guards.
std::vector<float> final_pixel_need(const Image& lv, const Image& hv, const Image& var_u, const Image& var_lv,
                                    const std::vector<uint32_t>& paths, float t);

// The largest need in the (2 radius + 1)^2 box around each pixel, the pixel itself left out (0 for
// a box of one pixel).
std::vector<float> neighbourhood_need(const std::vector<float>& need, int width, int height, int radius);

// a_p from the dilated need and the pixel's count (the minimum and the floor applied).
std::vector<float> sampling_rates(const std::vector<float>& dilated_need, const std::vector<uint32_t>& paths,
                                  const AdaptiveParams& params);

// The next frame's active mask from the rates: credit[p] += a_p, traced (1) when it reaches 1, which
// takes 1 off. `credit` starts at 0 per pixel and is carried from frame to frame.
std::vector<uint8_t> select_active(const std::vector<float>& rates, std::vector<float>& credit);

// Frame counts that grow with the render: `first`, then each time the frames grew by 1/divisor (at
// least by one). Built from the frames a render has done, it names the same later frames as the
// uninterrupted render's schedule: a resumed render checks and replans where that one did.
class GrowingSchedule {
 public:
  GrowingSchedule(int first, int divisor, int frames_done = 0) : next_(first), divisor_(divisor) {
    while (next_ <= frames_done) next_ = after(next_);
  }
  // Whether the count `frames` has reached the next scheduled one.
  bool due(int frames) const { return frames >= next_; }
  void done(int frames) { next_ = after(frames); }

 private:
  int after(int frames) const { return frames + (frames / divisor_ > 1 ? frames / divisor_ : 1); }
  int next_, divisor_;
};

// When `pxf render --until-clean` (and pxf bench --adaptive) asks whether the image is clean, by a
// fresh filter run and blend: from 16 frames on (fewer are never clean at a strict t), then
// whenever the frames grew by a quarter, so a render is found clean within 25 % of the frames it
// needed, at about log(n) / log(1.25) extra filter runs. due() takes the count after the frame.
inline GrowingSchedule clean_checks(int frames_done = 0) { return GrowingSchedule(16, 4, frames_done); }

// Counts of a frame's traced pixels, for stats.
struct SampleCounts {
  double mean = 0;
  uint32_t min = 0, max = 0;
};
SampleCounts sample_counts(const std::vector<uint32_t>& paths);

}  // namespace pxf
