// Adaptive sampling: how many paths each pixel traces in the next frame, from the
// method's own quantities. Pure functions on images and per-pixel counts, so that they are tested
// under a fake variance image (preview/adaptive_test.cpp); the preview (preview/preview.cpp) feeds them the
// accumulation.
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
//     dark, so that block means of the image come out low (tests/consistency_test.cpp;
//     docs/notebook/sampling.md has the figures). Decided by its neighbours, whose
//     samples are independent of its own, its count says nothing about its values. A caustic covers
//     more than one pixel, so its pixels keep each other sampled, and its quiet neighbours that
//     have not yet met its paths are sampled with it.
//   weight, goal Error (a render to a sample count or a time): s_p = sqrt(r_p n_p), the pixel's
//     per-path relative deviation over sqrt(t) (r falls as 1/n), r_p the neighbourhood's need:
//     paths in proportion to the standard deviation minimise the summed variance of the pixel
//     means for a given number of paths (sum sigma^2 / n under sum n fixed).
//   goal Clean (--until-clean): counts, not weights. x_q = r_q n_q is the count at which pixel q
//     would be at its threshold (its per-path perceived variance over t). From the OTHER pixels of
//     the box (so p's count says nothing about its values, as above) come two counts for p: the
//     typical one, the median x_q, and the full one N_p, clean_margin times the largest x_q, which
//     makes p clean whatever its own samples hold. Shortest lack first: the pixels short of their
//     typical count, in order of what they lack, then those short of their full count, in order of
//     theirs, each take what it lacks spread over the frames until the next replan (at most
//     max_rate), until the frame's paths are spent; the rest sit at the floor. Taking the shortest
//     jobs first is what makes the most pixels clean by any given time; the typical count first, so
//     that a pixel beside one hard neighbour is not funded to that neighbour's count before the
//     others are funded to theirs. Against the rule before it, which water-filled the lacks to N_p
//     (so that every pixel reached its count at once), it makes far more pixels clean early on and
//     the whole image clean in about as many frames (docs/notebook/sampling.md has the figures).
//     Not a rate from r_p alone: a rate in proportion to the
//     deviation (the rule of goal Error) went on sampling the neighbours of a pixel that one rare
//     path had made noisy, at max_rate, long after they were clean, and left that pixel at the
//     floor, so that it fell behind uniform sampling; a rate in proportion to the estimated
//     variance chased the pixels one rare path had just inflated and starved the rest.
//   minimum: a pixel with fewer than min_samples paths counts as at least at the threshold (r >= 1),
//     so that a pixel that only looks quiet (its rare bright paths not yet found) is not retired.
//   rate, goal Error: a_p = clamp(lambda w_p, floor_rate, max_rate) paths per frame, lambda such that the rates
//     add up to frame_paths per pixel (water filling): every frame traces as many paths as a uniform
//     one, spent where they help, and every pixel is traced at least every 1 / floor_rate frames.
//     Paths that no weight can take (every pixel short of paths at max_rate, the others at 0) go
//     to every pixel alike: the floor rises until the rates add up. The same for goal Clean: a
//     render whose pixels all reached their counts, yet some is not clean, samples uniformly from there.
//   selection: a per-pixel credit adds a_p each frame and the pixel traces floor(credit) paths,
//     which are taken off (error diffusion in time): deterministic, exactly a_p on average, no random
//     numbers.
#pragma once
#include <cstdint>
#include <limits>
#include <vector>

#include "image/image.h"

namespace pxf {

// What the allocation minimises (above): the error of the image at a given time, or the time until
// every pixel is clean.
enum class AdaptiveGoal { Error, Clean };

struct AdaptiveParams {
  // Uniform frames before the first allocation. 16: below it the per-pixel variances that rank the
  // pixels rest on too few samples (the threshold correction (n - 3) / (n - 1) is 0.87 at 16), and
  // 16 = 2^4 uniform frames give every pixel a complete (0, 4, 2)-net prefix of its Sobol sequence.
  uint32_t warmup_frames = 16;
  // A pixel with fewer paths is never retired to the floor: its need counts as at least 1.
  uint32_t min_samples = 64;
  // The least rate of any pixel: every pixel is traced at least every 16 frames.
  float floor_rate = 1.0f / 16.0f;
  // The most paths one pixel traces in a frame (the counts are bytes): a caustic that covers 2 % of
  // the image may take 32 times the mean.
  float max_rate = 32.0f;
  // Paths per frame, per pixel of the image: 1 keeps a frame as long as a uniform one, so that the
  // filter schedule and the per-frame work of the GL thread stay where they are.
  float frame_paths = 1.0f;
  AdaptiveGoal goal = AdaptiveGoal::Error;
  // Radius of the box whose other pixels decide a pixel's rate (2: the 5x5 window of the bias guard).
  int dilation_radius = 2;
  // Goal Clean: a pixel's predicted count is this times the largest count its neighbours need. Above
  // 1 because a pixel's own need is a draw like its neighbours': some pixels need more than the
  // largest of their neighbours, and the margin covers nearly all of them (docs/notebook/sampling.md
  // has the figures).
  float clean_margin = 1.5f;
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

// w_p of goal Error from the dilated need and the pixel's count, the minimum applied (+inf: an
// unknown variance).
std::vector<float> allocation_weights(const std::vector<float>& dilated_need, const std::vector<uint32_t>& paths,
                                      const AdaptiveParams& params);
// The median value among the OTHER pixels of the (2 radius + 1)^2 box around each pixel (the upper
// one of an even count; 0 for a box of one pixel).
std::vector<float> neighbourhood_median(const std::vector<float>& values, int width, int height, int radius);
// Goal Clean: the paths a pixel lacks to its typical count and to its full count (both at least
// min_samples), from each pixel's own need r (final_pixel_need) and count (see above).
struct CleanLack {
  float typical = 0.0f, full = 0.0f;
};
std::vector<CleanLack> clean_lacks(const std::vector<float>& need, const std::vector<uint32_t>& paths, int width,
                                   int height, const AdaptiveParams& params);
// Goal Clean's rates: shortest lack first (see above), each pixel taking at most its lack / horizon
// (the frames until the rates are recomputed) and max_rate, the others at floor_rate; paths left
// when every lack is served raise the floor, as in water_fill.
std::vector<float> shortest_lack_first(const std::vector<CleanLack>& lacks, double total, float floor_rate,
                                       float max_rate, double horizon);
// The rates clamp(lambda w_p, floor_rate, max_rate) that add up to `total`, or as near as the
// clamps let them (an infinite weight takes max_rate, a zero one floor_rate).
std::vector<float> water_fill(const std::vector<float>& weights, double total, float floor_rate, float max_rate);
// a_p (paths per frame): water_fill of goal Error's allocation_weights to params.frame_paths per pixel.
std::vector<float> sampling_rates(const std::vector<float>& dilated_need, const std::vector<uint32_t>& paths,
                                  const AdaptiveParams& params);
// a_p of params.goal from each pixel's own need r_p (final_pixel_need) and count: goal Error's
// weights (on neighbourhood_need) water-filled, or goal Clean's shortest lack first.
std::vector<float> allocation_rates(const std::vector<float>& need, const std::vector<uint32_t>& paths, int width,
                                    int height, const AdaptiveParams& params);

// The next frame's path count per pixel from the rates: credit[p] += a_p, and the pixel traces
// floor(credit[p]) paths, which are taken off. `credit` starts at 0 per pixel and is carried from
// frame to frame.
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

// When `pxf render --until-clean` (and pxf bench adaptive) asks whether the image is clean, by a
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
