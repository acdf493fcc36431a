// Parameters and codes of the preview passes (docs/method.md sections 2-4), shared by the GL passes, the CPU
// reference and the app (implemented in gl/pass_params.cpp). No GL here. The constants and formulas the shaders
// use too are in shaders/pass_formulas.h.
#pragma once
#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "image/tonemap.h"
#include "shaders/pass_formulas.h"

namespace pxf {

// The shared constants (shaders/pass_formulas.h) under their C++ names.
using shared::kAlbedoEpsilon;
using shared::kBackgroundDepth;
using shared::kBackgroundDistanceMin;
using shared::kBlendCaseCount;
using shared::kCaseLeastVariance;
using shared::kCaseMixed;
using shared::kCaseNoFiltered;
using shared::kCaseUnfiltered;
using shared::kCaseUnknownVar;
using shared::kCaseBiasGuard;
using shared::kMaxInput;
using shared::kVarSkipped;
using shared::kVarSkippedBelow;
using shared::kVarUnknown;
// Inputs are clamped to the tone map's largest input, so that every pass's output tone-maps.
static_assert(kMaxInput == kMaxTonemapInput);

// Cross bilateral filter variants: "bilateral-depth" (the full weight: spatial x color x depth) and
// "bilateral" (spatial x color, no depth term) are the exact square kernel; "separable" is the
// bilateral-depth weight applied as a horizontal then a vertical 1D pass (an approximation of
// the 2D kernel, about 2r+1 times cheaper; its Var[L_f] is exact for what it computes); "atrous"
// is the edge-avoiding à-trous wavelet (Dammertz et al. 2010): atrous_iterations(sigma_s) passes of
// a 5x5 B3-spline kernel with hole spacing 2^i, each tap weighted by the same color x depth range
// weights (25 taps per pass; its Var[L_f] treats each pass's inputs as independent, see
// gl/pass_params.cpp); "subsampled" is the bilateral-depth kernel evaluated at subsampled_taps()
// only: Poisson-disk offsets drawn from the spatial Gaussian (the tap density carries the spatial
// weight), rotated per pixel (Banterle et al. 2012), each weighted by the color x depth range
// weights; its Var[L_f] is exact for the weights it uses. "grid" is the bilateral grid (Chen et al.
// 2007) on the range color's luminance (gl/grid_layout.h).
// None: no filter (plain path tracing); the preview never runs the filter pass with it.
enum class FilterKind { BilateralDepth, Bilateral, Separable, Atrous, Subsampled, Grid, None };
// "bilateral-depth", "bilateral", "separable", "atrous", "subsampled", "grid": the filter pass's variants
// (FilterKind::None is named "none" by filter_kind_name and preview/preview.h's filter_option_names).
const std::vector<std::string>& filter_kind_names();
const char* filter_kind_name(FilterKind kind);
FilterKind parse_filter_kind(const std::string& name);  // throws pxf::Error listing the names

struct FilterParams {
  FilterKind kind = FilterKind::Grid;  // cheapest and most accurate on llvmpipe: README "Filter variants"
  float sigma_s = 8.0f;   // pixels; kernel radius ceil(3 sigma_s), at most kMaxFilterRadius
  float sigma_c = 0.02f;  // range color, Euclidean distance in linear RGB
  float sigma_d = 2.0f;   // depth, scene units
  // The surface terms (shaders/pass_formulas.h surface_exponent, docs/method.md 2.1): the angle
  // between shading normals, radians, and the roughness difference; 0 turns a term off. Tight
  // enough that a normal map's bumps and a roughness map's pattern stop the kernel at any sigma_s,
  // wide enough that a smooth curved surface still averages over several pixels.
  float sigma_n = 0.15f;
  float sigma_r = 0.1f;
  // The à-trous variant's luminance edge stop (shaders/pass_formulas.h luminance_edge_exponent), in
  // standard deviations of the signal; 0 turns it off. SVGF's value.
  float sigma_l = 4.0f;
  // Skip pixels in case 2 (u <= t, t the blend threshold every filter run is given): they need no
  // filtered value. u is computed with the *unfiltered* background L_b = Y(L_u) + Y(L_lv), so the
  // decision needs no history; a skipped pixel gets L_f = L_u and Var[L_f] = kVarSkipped, and the
  // blend uses s = 1 there.
  bool skip_case2 = true;
  // Skip by the halves of the split decision (BlendParams::split, shared::skip_as_case2_by_halves):
  // only pixels where both halves' decisions are case 2, where the inputs hold the halves.
  bool split = false;
  int subsampled_taps = 0;  // taps of the subsampled variant, the centre included; 0 = kSubsampledTaps
};
// The skip a filter run applies (the shaders' skip_case2 uniform, shared::skip_pixel): none, by
// the pixel's own variance, or by its halves' where the inputs hold them (PreviewInputs::has_halves).
inline int filter_skip_mode(const FilterParams& p, bool inputs_have_halves) {
  if (!p.skip_case2) return shared::kSkipOff;
  return p.split && inputs_have_halves ? shared::kSkipByHalves : shared::kSkipOn;
}
constexpr int kMaxFilterRadius = 64;

// The subsampled variant's taps per pixel, the centre included: chosen by measurement of time
// against HV-only NRMSE at 4 spp (docs/filter-subsampled.md).
constexpr int kSubsampledTaps = 32;
// Rotations of the tap pattern; each pixel uses rotation subsampled_rotation(x, y).
constexpr int kSubsampledRotations = 64;
// One entry of the tap table: the pixel offset and how many of the pattern's taps rounded to it
// (its weight factor); count 0 pads a rotation's list to the common length.
struct SubsampledTap {
  int dx = 0, dy = 0, count = 0, unused = 0;  // 16 bytes: an ivec4 in the shader's std430 buffer
};
// The table of all rotations: rotation r's taps are taps[r * per_rotation, (r + 1) * per_rotation).
// The one definition used by the GL pass (uploaded as a buffer) and the CPU reference.
struct SubsampledTapTable {
  int per_rotation = 0;
  std::vector<SubsampledTap> taps;
};
SubsampledTapTable subsampled_tap_table(float sigma_s, int taps);
// The pattern rotation of pixel (x, y): shared::subsampled_rotation (the shader's).
inline int subsampled_rotation(int x, int y) { return shared::subsampled_rotation(glm::ivec2(x, y), kSubsampledRotations); }

// 1 / (2 sigma^2), sigma clamped away from 0.
constexpr float inv_two_sigma2(float sigma) {
  const float s = std::max(sigma, 1.0e-6f);
  return 1.0f / (2.0f * s * s);
}
// The range weight exp(-|R(p)-R(q)|^2 k_c - (d(p)-d(q))^2 k_d - surface terms) of a filter: k_d = 0
// for the color-only variant; k_n = 1 / sigma_n^2 and k_r = 1 / (2 sigma_r^2), 0 where that sigma is
// 0 (term off). The blend's variance pooling uses the same weights as the filter.
struct RangeWeights {
  float k_c = 0.0f, k_d = 0.0f, k_n = 0.0f, k_r = 0.0f;
};
constexpr float inv_sigma2_or_off(float sigma, float factor) {
  return sigma > 0.0f ? factor / (sigma * sigma) : 0.0f;
}
constexpr RangeWeights range_weights(const FilterParams& p) {
  return {inv_two_sigma2(p.sigma_c), p.kind != FilterKind::Bilateral ? inv_two_sigma2(p.sigma_d) : 0.0f,
          inv_sigma2_or_off(p.sigma_n, 1.0f), inv_sigma2_or_off(p.sigma_r, 0.5f)};
}

// k_l = 1 / sigma_l of the à-trous luminance edge stop, 0 where it is off.
constexpr float atrous_k_l(const FilterParams& p) { return p.sigma_l > 0.0f ? 1.0f / p.sigma_l : 0.0f; }

// Passes of the à-trous variant for sigma_s (rule in gl/pass_params.cpp), at least 1, and few
// enough that its footprint radius 2 (2^k - 1) stays within kMaxFilterRadius.
int atrous_iterations(float sigma_s);
// Factor on the Var[L_f] that à-trous pass `pass` (from 0) propagates as if its input pixels were
// independent, so that it is exact where the range weights are all 1 (see pass_params.cpp).
float atrous_variance_correction(int pass);

// The threshold the blend and the filter's case-2 skip are given after n samples per pixel:
// t (n - 3) / (n - 1), t itself as n grows (docs/method.md, "The threshold after few samples").
// Why: the blend solves for s with the *estimated* Var[L_u], and where u dominates, s^2 is about
// t / u_hat. With a sample variance of k = n - 1 degrees of freedom, E[1 / S^2] = k / (k - 2) / sigma^2
// (Gaussian samples), so the perceived variance the blend leaves is on average t (n - 1) / (n - 3):
// 15 % over t at 16 spp. E[1 / S^2] is infinite for n <= 3; there the n = 4 factor 1/3 is used.
float effective_threshold(float t, uint64_t samples);

// The spatial sigma of a filter run, when the preview shrinks it to the noise
// (PreviewSettings::shrink_sigma, on by default; docs/method.md 2.5). The filter has to bring a
// pixel's perceived variance u down to about t: a Gaussian average of independent neighbours of
// sigma s divides it by 4 pi s^2, so the pixel needs s = sqrt((u / t) / (4 pi)). The kernel is
// sized for the noisy pixels' kSigmaNoiseQuantile-quantile of u / t (`needed`: u / t of every
// pixel with u > t, in any order; it is reordered), never above sigma_s nor below kSigmaShrinkMin
// (a sigma_s already below it is kept), and sigma_s itself up to kSigmaShrinkFromSpp samples, whose
// variance estimates are too few to go by. A narrower kernel averages light over less of the
// scene: less bias where the noise allows it, the full kernel where it does not.
constexpr uint64_t kSigmaShrinkFromSpp = 4;
constexpr float kSigmaShrinkMin = 2.0f;
constexpr double kSigmaNoiseQuantile = 0.9;
float noise_sigma_s(float sigma_s, uint64_t samples, std::vector<float>& needed);

// The blend's parameters besides its threshold t (the perceived-variance threshold, sqrt(t) = the
// allowed relative standard deviation), which every run is given next to them.
struct BlendParams {
  // Weights of the 3x3 variance pooling (pooled_var_u in shaders/pass_formulas.h): the filter's.
  RangeWeights range = range_weights(FilterParams{});
  // Raise s where L_f is measurably biased (bias_guard_factor in shaders/pass_formulas.h, case
  // kCaseBiasGuard). Off here, the method's blend as published; the preview's
  // default turns it on (PreviewSettings).
  bool bias_guard = false;
  // The run's sample count n, from which the zero-variance rule's decay reads each pixel's own
  // (shared::zero_variance_u, shared::pixel_samples); 0: unknown, no decay.
  float samples = 0.0f;
  // Blend each half of the pixel's samples with the weight the other half's variance decides
  // (blend_pixel_split, docs/method.md section 3.8), where the inputs hold the halves
  // (PreviewInputs::has_halves). Off, the method's blend as published, here and in the preview
  // unless TraceParams::split_halves (--split-decision) keeps the halves.
  bool split = false;
};

// TonemapParams: image/tonemap.h (the tone map formula lives there).

}  // namespace pxf
