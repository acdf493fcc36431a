// Plain C++ implementation of the preview passes (docs/method.md sections 2, 3, 5) on pxf::Image: the reference the
// GL shaders are tested against. The per-pixel formulas are the shaders' own (shaders/pass_formulas.h, compiled
// here as C++); the kernels' loops are written again here, with sums in double.
// Images: L_u "R,G,B"; L_lv "R,G,B", or "R,G,B,A" with A each pixel's threshold factor (the GL
// texture's alpha, shared::pixel_threshold: the threshold there is t A; "R,G,B" reads A = 1);
// Var[L_u] one channel (kVarUnknown where n < 2; exactly 0 where all
// n >= 2 samples were equal, which the filter and blend do not trust as low variance); the range guide
// "R,G,B" + depth one channel. Every function sanitizes exactly like the shaders (non-finite
// inputs read as 0, magnitudes clamped to kMaxInput), so outputs are always finite.
#pragma once
#include <array>
#include "gl/pass_params.h"
#include "image/image.h"

namespace pxf {

// The shaders' input sanitizing: clean() non-finite -> 0, magnitude clamped to kMaxInput;
// clean_var() negative or non-finite variance -> kVarUnknown.
using shared::clean;
using shared::clean_var;
// var / lb^2 without overflow in the intermediate: 0 when var <= 0, +inf when lb <= 0.
using shared::relative_variance;
// u of a pixel whose samples were all equal (Var[L_u] = 0, n >= 2): (Y(L_f) / L_b)^2, falling as
// 1 / n from kZeroVarianceSamples on; the pixel's own n from its threshold factor: pixel_samples.
using shared::kZeroVarianceSamples;
using shared::pixel_samples;
using shared::zero_variance_u;

struct BlendDecision {
  float s = 1.0f;
  int blend_case = kCaseUnfiltered;
};
// The blend case logic (docs/method.md section 3.2): shared::blend_factor on relative variances u, f
// and threshold t.
BlendDecision blend_decision(float u, float f, float t);
// The same with the covariance of L_u and L_f (w: the filter's normalized centre weight):
// shared::blend_factor_covariance.
BlendDecision blend_decision(float u, float f, float t, float w);
inline float blend_factor(float u, float f, float t) { return blend_decision(u, f, t).s; }
// shared::pooled_var_u on images: max of the pixel's own variance and the range-weighted mean of
// the known (> 0) variances of its 3x3 neighbourhood. kVarUnknown where the own variance is
// unknown (n < 2); 0 where it is 0 and no neighbour's is known.
float pooled_var_u(const Image& var_u, const Image& range_color, const Image& depth, int x, int y,
                   const RangeWeights& range, const Image* surface = nullptr);

struct FilterOutput {
  Image filtered;  // "R,G,B": L_f (L_u where skipped)
  Image variance;  // "Y": Var[L_f]; kVarUnknown, or kVarSkipped where skipped
  // "Y": the normalized weight of the pixel's own L_u in its L_f (1 / sum w for the full bilateral
  // kernel, 1 where skipped), for the blend's covariance term; empty for the other variants.
  Image centre_weight;
};
// t: the blend threshold, for the case-2 skip. surface: the range pass's surface buffer ("X,Y,Z,R":
// shading normal, roughness) for the range weight's surface terms; nullptr: none (terms left out).
// half_variances: the split decision's (two channels, V_even and V_odd, PreviewInputs::upload_halves),
// which the skip reads under params.split (filter_skip_mode); nullptr: none.
FilterOutput cpu_filter(const Image& hv, const Image& var_u, const Image& lv, const Image& range_color,
                        const Image& depth, const FilterParams& params, float t, const Image* surface = nullptr,
                        const Image* half_variances = nullptr);

// The filter's case-2 skip (FilterParams::skip_case2, final pass only): the blend's u (pooled
// variance) with the unfiltered background; a zero variance is not trusted. Writes the skip
// (L_f = L_u, Var = kVarSkipped) into `out` and returns true where the pixel is skipped.
bool skip_as_case2(const Image& hv, const Image& var_u, const Image& lv, const Image& range_color,
                   const Image& depth, const FilterParams& p, float t, int x, int y, FilterOutput& out,
                   const Image* surface = nullptr, const Image* half_variances = nullptr);

// The filter's case-2 skip decision alone (what skip_as_case2 tests): shared::skip_pixel.
bool case2_skip_decision(const Image& hv, const Image& var_u, const Image& lv, const Image& range_color,
                         const Image& depth, const FilterParams& p, float t, int x, int y,
                         const Image* surface = nullptr, const Image* half_variances = nullptr);

// Albedo demodulation (gl/demodulation.h): shared::demodulated_texel and shared::remodulated_texel.
struct DemodulatedInputs {
  Image hv;     // "R,G,B" and
  Image var_u;  // "Y": shared::demodulated_texel
  Image lv;     // "R,G,B": the skip decision on the original buffers: +kMaxInput skip, -kMaxInput filter
};
// The filter's inputs under demodulation; albedo "R,G,B" (the mean first non-specular albedo).
DemodulatedInputs cpu_demodulate(const Image& hv, const Image& var_u, const Image& lv, const Image& albedo,
                                 const Image& range_color, const Image& depth, const FilterParams& params, float t,
                                 const Image* surface = nullptr, const Image* half_variances = nullptr);
// shared::remodulated_texel of every pixel.
FilterOutput cpu_remodulate(const FilterOutput& filtered, const Image& albedo);

struct BlendOutput {
  Image final_rgb;   // "R,G,B"
  Image s;           // "Y"
  Image blend_case;  // "Y": case codes (kCase*)
};
// The halves of the split decision (PreviewInputs::upload_halves): rgb L_even, a n_even / n; and
// the whole mean's variance from each half alone ("even", "odd" channels).
struct BlendHalves {
  const Image* halves = nullptr;
  const Image* variances = nullptr;
};
// `filtered` empty = the filter never ran. range_color and depth both null: no variance pooling.
// surface: as cpu_filter's, for the pooling's range weights. With params.split and halves given,
// shared::blend_pixel_split.
BlendOutput cpu_blend(const Image& lv, const Image& hv, const Image& var_u, const FilterOutput* filtered, float t,
                      const BlendParams& params, const Image* range_color, const Image* depth,
                      const Image* surface = nullptr, BlendHalves halves = {});

double cpu_log_average(const Image& rgb, float delta);
Image cpu_tonemap(const Image& rgb, const TonemapParams& params);  // "R,G,B" display values in [0,1]

}  // namespace pxf
