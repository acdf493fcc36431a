// Plain C++ implementation of the preview formulas (docs/method.md sections 2, 3, 5) on pxf::Image: the reference the
// GL shaders are tested against, and the single CPU definition of the blend case logic.
// Images: L_u/L_lv "R,G,B"; Var[L_u] one channel (kVarUnknown where n < 2; exactly 0 where all
// n >= 2 samples were equal, which the filter and blend do not trust as low variance); the range guide
// "R,G,B" + depth one channel. Every function sanitizes exactly like the shaders (non-finite
// inputs read as 0, magnitudes clamped to kMaxInput), so outputs are always finite.
#pragma once
#include <array>
#include "gl/preview_params.h"
#include "image/image.h"

namespace pxf {

struct BlendDecision {
  float s = 1.0f;
  int blend_case = kCaseUnfiltered;
};
// The blend case logic (docs/method.md section 3.2) on relative variances u, f (>= 0, may be +inf) and threshold t, computed
// after scaling by max(u, f) so that no intermediate overflows: case 2 (u <= t) first, then
// case 1 (D < 0), else case 3. NaN u or f count as +inf, NaN or negative t as 0.
BlendDecision blend_decision(float u, float f, float t);
// The same with the covariance of L_u and L_f: the filter averages each pixel's own samples with
// normalized centre weight w (0..1), so Cov[L_u, L_f] = w Var[L_u] and the blend's relative
// variance is g(s) = s^2 u + (1-s)^2 f + 2 s (1-s) w u. Case 2 as above; case 1 where t is below
// the minimum of g on [0, 1]: (u f - c^2) / (u + f - 2c) with c = w u (clamped to sqrt(u f),
// Cauchy-Schwarz), or f where that minimum lies at s < 0 (c > f); case 3 the larger root of g(s) = t. w <= 0 (or NaN), or u or f infinite: blend_decision(u, f, t).
BlendDecision blend_decision(float u, float f, float t, float w);
inline float blend_factor(float u, float f, float t) { return blend_decision(u, f, t).s; }
// var / lb^2 without overflow in the intermediate: 0 when var <= 0, +inf when lb <= 0.
float relative_variance(float var, float lb);
// u of a pixel whose samples were all equal (Var[L_u] = 0, n >= 2): (Y(L_f) / L_b)^2, as if its
// mean's variance were Y(L_f)^2 (a mean of L_f fits such samples as well as their own mean).
float zero_variance_u(float y_f, float lb);
// Var[L_u] for the blend decision and the filter's skipping: max of the pixel's own variance and
// the range-weighted mean of the known (> 0) variances of its 3x3 neighbourhood. kVarUnknown where
// the own variance is unknown (n < 2); 0 where it is 0 and no neighbour's is known. Why: see
// pooled_var_u in shaders/common.glsl.
float pooled_var_u(const Image& var_u, const Image& range_color, const Image& depth, int x, int y,
                   const RangeWeights& range);

struct FilterOutput {
  Image filtered;  // "R,G,B": L_f (L_u where skipped)
  Image variance;  // "Y": Var[L_f]; kVarUnknown, or kVarSkipped where skipped
  // "Y": the normalized weight of the pixel's own L_u in its L_f (1 / sum w for the full bilateral
  // kernel, 1 where skipped), for the blend's covariance term; empty for the other variants.
  Image centre_weight;
};
// t: the blend threshold, for the case-2 skip.
FilterOutput cpu_filter(const Image& hv, const Image& var_u, const Image& lv, const Image& range_color,
                        const Image& depth, const FilterParams& params, float t);

// The shaders' clean(): non-finite -> 0, magnitude clamped to kMaxInput; clean_var(): negative or
// non-finite variance -> kVarUnknown. For the variants' references in other files.
float clean(float v);
float clean_var(float v);
// The filter's case-2 skip (FilterParams::skip_case2, final pass only): the blend's u (pooled
// variance) with the unfiltered background; a zero variance is not trusted. Writes the skip
// (L_f = L_u, Var = kVarSkipped) into `out` and returns true where the pixel is skipped.
bool skip_as_case2(const Image& hv, const Image& var_u, const Image& lv, const Image& range_color,
                   const Image& depth, const FilterParams& p, float t, int x, int y, FilterOutput& out);

// The filter's case-2 skip decision alone (what skip_as_case2 tests).
bool case2_skip_decision(const Image& hv, const Image& var_u, const Image& lv, const Image& range_color,
                         const Image& depth, const FilterParams& p, float t, int x, int y);

// Albedo demodulation (gl/demodulation.h). The factor: grey Y(albedo) where that is at least
// kAlbedoEpsilon, else (1, 1, 1) (that pixel is not demodulated).
std::array<float, 3> demodulation_factor(float r, float g, float b);
struct DemodulatedInputs {
  Image hv;     // "R,G,B": L_u / a
  Image var_u;  // "Y": Var[L_u] / Y(a)^2 (sentinels kept)
  Image lv;     // "R,G,B": the skip decision on the original buffers: +kMaxInput skip, -kMaxInput filter
};
// The filter's inputs under demodulation; albedo "R,G,B" (the mean first non-specular albedo).
DemodulatedInputs cpu_demodulate(const Image& hv, const Image& var_u, const Image& lv, const Image& albedo,
                                 const Image& range_color, const Image& depth, const FilterParams& params, float t);
// L_f = a L_f', Var[L_f] = Y(a)^2 Var[L_f'] (sentinels kept).
FilterOutput cpu_remodulate(const FilterOutput& filtered, const Image& albedo);

struct BlendOutput {
  Image final_rgb;   // "R,G,B"
  Image s;           // "Y"
  Image blend_case;  // "Y": BlendCase codes
};
// `filtered` empty = the filter never ran. range_color and depth both null: no variance pooling.
BlendOutput cpu_blend(const Image& lv, const Image& hv, const Image& var_u, const FilterOutput* filtered, float t,
                      const BlendParams& params, const Image* range_color, const Image* depth);

double cpu_log_average(const Image& rgb, float delta);
Image cpu_tonemap(const Image& rgb, const TonemapParams& params);  // "R,G,B" display values in [0,1]

}  // namespace pxf
