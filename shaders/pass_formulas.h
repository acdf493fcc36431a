// The formulas and constants of the preview passes (docs/method.md sections 2-4) that the shaders
// and the CPU reference (gl/cpu_reference.cpp, gl/grid_reference.cpp) both compute: one source,
// valid GLSL and C++ (shaders/cpu_gpu.h). The gl_tests compare the two compilations of it.
#ifdef __cplusplus
#pragma once  // also included by shaders/history_formulas.h
#endif
#include "cpu_gpu.h"

PXF_SHARED_BEGIN

// ---- Constants ----

// Inputs larger than this are clamped, so that sums of a whole kernel stay finite in float.
PXF_CONST float kMaxInput = 1.0e30f;
PXF_CONST float kInf = PXF_INFINITY;

// Sentinels of the variance channels (alpha of the HV and filtered textures).
PXF_CONST float kVarUnknown = -1.0f;  // n < 2 (Var[L_u]); no known neighbour variance (Var[L_f])
PXF_CONST float kVarSkipped = -2.0f;  // Var[L_f] of a pixel the filter skipped (case 2)
// A Var[L_f] below this is kVarSkipped (halfway between the two sentinels).
PXF_CONST float kVarSkippedBelow = -1.5f;

// Blend case per pixel (the "case" buffer), tested in the order of docs/method.md section 3.2.
PXF_CONST int kCaseNoFiltered = 0;    // no L_f exists yet (the filter never ran): s = 1
PXF_CONST int kCaseLeastVariance = 1;  // D < 0, no s reaches t: the s of least variance (mostly L_f)
PXF_CONST int kCaseUnfiltered = 2;    // u <= t (or the filter skipped the pixel): s = 1
PXF_CONST int kCaseMixed = 3;         // s = (f + sqrt(D)) / (u + f)
PXF_CONST int kCaseUnknownVar = 4;    // n < 2, variance unknown: s = 0 (filtered value only)
PXF_CONST int kCaseBiasGuard = 5;     // case 1 or 3 whose L_f is measurably biased: s raised to the least-error s
PXF_CONST int kBlendCaseCount = 6;
// The color of each case in the explorer's case view and its legend; yellow for any other code.
PXF_INLINE vec3 case_color(int code) {
  if (code == kCaseNoFiltered) return vec3(0.35f, 0.35f, 0.35f);
  if (code == kCaseLeastVariance) return vec3(0.90f, 0.20f, 0.15f);
  if (code == kCaseUnfiltered) return vec3(0.20f, 0.75f, 0.25f);
  if (code == kCaseMixed) return vec3(0.20f, 0.45f, 0.95f);
  if (code == kCaseUnknownVar) return vec3(0.85f, 0.30f, 0.85f);
  if (code == kCaseBiasGuard) return vec3(0.10f, 0.85f, 0.85f);
  return vec3(1.0f, 1.0f, 0.0f);
}

// Background depth (distance) of the range buffer where no surface is hit.
PXF_CONST float kBackgroundDepth = 1.0e4f;
// The blend's background rule: a pixel whose guide distance is at least this (mostly background)
// and whose L_u is exactly 0 saw no HV light: its camera rays escaped, so there was none to miss,
// and no L_f is blended in (case 2, s = 1). Without it, the zero-variance rule lets filtered light
// of the objects before an environment bleed into it as a halo.
PXF_CONST float kBackgroundDistanceMin = 0.5f * kBackgroundDepth;
// The a-trous filter's background skip: a pixel whose guide saw the background in (nearly) every
// antialiasing frame. Its range weight to any surface pixel is 0 (the distance term underflows), and
// every pixel it weighs is background too, so the filter leaves it as it is, for two reads instead
// of 25 taps (an object under a sky is mostly sky); the final pass marks it kVarSkipped and the
// blend shows L_u there.
PXF_CONST float kBackgroundOnlyDistance = 0.99f * kBackgroundDepth;

// Albedo demodulation (gl/demodulation.h): a pixel whose mean albedo's luminance is below this is
// not demodulated (factor 1), so that dividing never amplifies by more than 1 / kAlbedoEpsilon.
// The mean albedo is coverage times albedo (PathSample::albedo), and HV shrinks with it, so the
// division is exact down to a pixel that a dark surface barely touches.
PXF_CONST float kAlbedoEpsilon = 1e-3f;

// Texture units of the pass shaders (filters, demodulation, blend), one per role: the GL passes
// bind their textures to these names.
PXF_CONST int kUnitHv = 0;            // rgb L_u, a Var[L_u]
PXF_CONST int kUnitLv = 1;            // rgb L_lv
PXF_CONST int kUnitGuide = 2;         // rgb range color, a distance
PXF_CONST int kUnitSignal = 3;        // what a filter pass filters: L_u, or the previous pass's output
PXF_CONST int kUnitFiltered = 4;      // rgb L_f, a Var[L_f] or a sentinel
PXF_CONST int kUnitCentreWeight = 5;  // r: the filter's centre weight
PXF_CONST int kUnitAlbedo = 6;        // rgb mean first non-specular albedo
// the bias guard's finding (b2, var_u; with halves, the even half's then the odd's), or the row
// sums over x in [-r, r]
PXF_CONST int kUnitGuardSums = 7;
PXF_CONST int kUnitGuardRowsLowX = 8;   // the bias guard's row sums over x in [-r, 0]
PXF_CONST int kUnitGuardRowsHighX = 9;  // and over x in [0, r]
PXF_CONST int kUnitSurface = 10;      // the range buffer's surface: xyz shading normal (0: unknown), w roughness
PXF_CONST int kUnitHalves = 11;       // the split decision: rgb L_even, a n_even / n
PXF_CONST int kUnitHalfVariances = 12;  // rg: the whole mean's variance from each half alone (even, odd)

// Shader storage buffer bindings of the pass shaders.
PXF_CONST int kBufferCounts = 0;      // the filters' filtered-pixel counter, the blend's case counts
PXF_CONST int kBufferGrid = 1;        // the bilateral grid's cells (read by the blur and the slice)
PXF_CONST int kBufferGridTarget = 2;  // the grid blur's output
PXF_CONST int kBufferTaps = 3;        // the subsampled variant's tap table
PXF_CONST int kBufferGridBounds = 4;  // the guide's luminance bounds (grid_bounds.comp)

// ---- Input sanitizing ----

// Rec. 709 luminance of linear RGB.
PXF_INLINE float luminance(vec3 c) { return dot(c, vec3(0.2126f, 0.7152f, 0.0722f)); }

// Non-finite -> 0, magnitude clamped (so kernel sums stay finite in float).
PXF_INLINE float clean(float v) { return (isnan(v) || isinf(v)) ? 0.0f : clamp(v, -kMaxInput, kMaxInput); }
PXF_INLINE vec3 clean(vec3 c) { return vec3(clean(c.r), clean(c.g), clean(c.b)); }
// Variance channel: negative or non-finite = unknown.
PXF_INLINE float clean_var(float v) { return (isnan(v) || isinf(v) || v < 0.0f) ? kVarUnknown : min(v, kMaxInput); }

// ---- Range weights ----

// The surface term of the range weight (docs/method.md section 2.1) between surface texels (xyz the
// shading normal, w the roughness; the range pass's antialiasing averages them, so the normal is
// not unit length at edges): (1 - cos(n_p, n_q)) k_n + (r_p - r_q)^2 k_r. 1 - cos is about
// angle^2 / 2 for small angles, so with k_n = 1 / sigma_n^2 the normal term is a Gaussian of the
// angle with deviation sigma_n (radians); unlike SVGF's max(0, cos)^sigma_n it stays above 0 for
// opposite normals, so it is one more addend of the one exponent. Where either normal is unknown
// (the environment, a specular chain without an end, no surface buffer: a normal shorter than
// kMinSurfaceNormal) the term is 0: the colour and distance terms alone decide there.
PXF_CONST float kMinSurfaceNormal = 0.25f;
// The normal term narrows with the sharper of the two surfaces' glossy lobes: the light a lobe of
// GGX alpha = roughness^2 reflects changes over normals about alpha / 2 apart, so a highlight on a
// curved glossy surface must not be spread over its neighbours. sigma_n applies from roughness
// kLobeRoughnessWide up (nearly diffuse surfaces); below it sigma_n roughness / kLobeRoughnessWide,
// at least kLobeNarrowest sigma_n. Linear in the roughness rather than in alpha: the sharpest lobes
// keep a few pixels' averaging on a smooth surface, and the weight does not hang on the roughness's
// last bits.
PXF_CONST float kLobeRoughnessWide = 0.8f;
PXF_CONST float kLobeNarrowest = 0.1f;
PXF_INLINE wide_float lobe_normal_scale(float roughness_p, float roughness_q) {
  float r = clamp(min(roughness_p, roughness_q), 0.0f, 1.0f);
  wide_float s = wide_float(clamp(r * (1.0f / kLobeRoughnessWide), kLobeNarrowest, 1.0f));
  return 1.0f / (s * s);
}
PXF_INLINE wide_float surface_exponent(vec4 s_p, vec4 s_q, float k_n, float k_r) {
  if (!(k_n > 0.0f) && !(k_r > 0.0f)) return 0.0f;
  vec3 a = clean(vec3(s_p)), b = clean(vec3(s_q));
  float la = dot(a, a), lb = dot(b, b);
  if (!(la >= kMinSurfaceNormal * kMinSurfaceNormal) || !(lb >= kMinSurfaceNormal * kMinSurfaceNormal)) return 0.0f;
  // 1 - cos = |a/|a| - b/|b||^2 / 2, which keeps its precision for nearly equal normals, where the
  // narrow lobes' scale (up to 2500) would magnify the rounding of 1 - cos.
  wide_vec3 d = wide_vec3(a) / sqrt(wide_float(la)) - wide_vec3(b) / sqrt(wide_float(lb));
  wide_float one_minus_cos = 0.5f * dot(d, d);
  wide_float dr = wide_float(clean(s_p.a)) - wide_float(clean(s_q.a));
  wide_float lobe = lobe_normal_scale(clean(s_p.a), clean(s_q.a));
  return one_minus_cos * k_n * lobe + dr * dr * k_r;
}

// The exponent of the cross bilateral filter's range weight between guide texels g (rgb range
// color, a distance) and surface texels s: |R(p) - R(q)|^2 k_c + (d(p) - d(q))^2 k_d + the surface
// term (surface_exponent; k_n = k_r = 0 leaves it out).
PXF_INLINE wide_float range_exponent(vec4 g_p, vec4 g_q, vec4 s_p, vec4 s_q, float k_c, float k_d, float k_n,
                                     float k_r) {
  wide_vec3 dr = wide_vec3(clean(vec3(g_p)) - clean(vec3(g_q)));
  wide_float dd = wide_float(clean(g_p.a)) - wide_float(clean(g_q.a));
  return dot(dr, dr) * k_c + dd * dd * k_d + surface_exponent(s_p, s_q, k_n, k_r);
}
PXF_INLINE wide_float range_weight(vec4 g_p, vec4 g_q, vec4 s_p, vec4 s_q, float k_c, float k_d, float k_n,
                                   float k_r) {
  return exp(-range_exponent(g_p, g_q, s_p, s_q, k_c, k_d, k_n, k_r));
}

// The à-trous variant's luminance edge stop (after SVGF, Schied et al. 2017), an addend of the
// range exponent between p and q: with x = |Y(l_p) - Y(l_q)| / (sigma_l sqrt(Var_p)), k_l = 1 /
// sigma_l and Var_p the variance of the signal at p in this pass, 4 max(0, x - 1)^2. It stops the
// kernel at edges of the light itself that the guide does not show (a shadow's edge, a highlight)
// once they stand out of the noise by more than sigma_l standard deviations, and is 0 below that:
// a difference the noise can make (nearly always under 4 of its deviations) leaves the weight
// alone, so the kernel stays independent of the noise and Var[L_f] stays what the sums claim. 0
// where Var_p is unknown or k_l is 0 (off); a noise-free pixel (Var_p = 0) keeps to neighbours
// equal to it.
PXF_INLINE wide_float luminance_edge_exponent(vec3 l_p, vec3 l_q, float var_p, float k_l) {
  if (!(k_l > 0.0f) || var_p < 0.0f) return 0.0f;
  wide_float d = abs(wide_float(luminance(l_p)) - wide_float(luminance(l_q)));
  if (!(d > 0.0f)) return 0.0f;
  wide_float sd = sqrt(wide_float(var_p));
  if (!(sd > 0.0f)) return wide_float(1e4f);
  wide_float x = max(min(d * wide_float(k_l) / sd, wide_float(100.0f)) - 1.0f, wide_float(0.0f));
  return 4.0f * x * x;
}

// The variance the luminance edge stop reads at p: the mean of the known variances of the signal
// over p's 3x3 neighbourhood (SVGF prefilters it too): a pixel's own estimate from few samples is
// itself noisy, and one that came out low would shut its neighbours out and keep its noise.
// kVarUnknown where none is known.
PXF_SAMPLER_FN float edge_stop_variance(sampler2D signal, ivec2 p) {
  ivec2 size = textureSize(signal, 0);
  float sum = 0.0f, count = 0.0f;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      ivec2 q = p + ivec2(dx, dy);
      if (q.x < 0 || q.y < 0 || q.x >= size.x || q.y >= size.y) continue;
      float v = clean_var(texelFetch(signal, q, 0).a);
      if (v >= 0.0f) {
        sum += v;
        count += 1.0f;
      }
    }
  return count > 0.0f ? sum / count : kVarUnknown;
}

// ---- Kernel sums ----

// Var[L_f] = factor (sum_known w^2 Var + sum_unknown w^2 vbar) / (sum w)^2 with vbar = sum_known w Var /
// sum_known w, the kernel-weighted mean of the known variances; kVarUnknown when none is known. The
// formula of every filter variant: the kernel sums below and the grid's slice (its cells carry the
// same sums through the blur). `factor` corrects for correlated inputs (à-trous, grid), else 1.
PXF_INLINE float propagated_variance(wide_float w, wide_float w2_var_known, wide_float w2_unknown, wide_float w_known,
                                     wide_float w_var_known, float factor) {
  if (!(w_known > 0.0f)) return kVarUnknown;
  return float(factor * (w2_var_known + w2_unknown * (w_var_known / w_known)) / (w * w));
}

// One pixel's sums over a filter kernel: L_f = sum w L / sum w and Var[L_f] = sum w^2 Var / (sum w)^2
// (the pixels' samples are independent). Neighbours of unknown variance (n < 2, or 0: all samples
// equal, no evidence) count with the kernel-weighted mean of the known ones. Every filter variant
// (bilateral, subsampled, à-trous) and the CPU reference accumulate through these.
struct KernelSums {
  wide_float w;             // sum w
  wide_vec3 wl;             // sum w L
  wide_float w2_var_known;  // sum w^2 Var over the neighbours of known variance
  wide_float w2_unknown;    // sum w^2 over the others
  wide_float w_known;       // sum w and sum w Var over the known ones: their weighted mean variance
  wide_float w_var_known;
};
PXF_INLINE KernelSums kernel_sums_zero() {
  KernelSums s;
  s.w = 0.0f;
  s.wl = wide_vec3(0.0f);
  s.w2_var_known = 0.0f;
  s.w2_unknown = 0.0f;
  s.w_known = 0.0f;
  s.w_var_known = 0.0f;
  return s;
}
// Tap of weight w, radiance l and variance var (clean_var: negative = unknown).
PXF_INLINE void kernel_sums_add(PXF_INOUT(KernelSums) s, wide_float w, vec3 l, float var) {
  s.w += w;
  s.wl += wide_vec3(l) * w;
  if (var > 0.0f) {
    s.w2_var_known += w * w * var;
    s.w_known += w;
    s.w_var_known += w * var;
  } else {
    s.w2_unknown += w * w;
  }
}
// s.w > 0 in every filter: the centre tap has range weight 1.
PXF_INLINE vec3 kernel_sums_mean(KernelSums s) { return vec3(s.wl / s.w); }
// Var[L_f] times `factor` (the à-trous correction for correlated inputs, else 1); kVarUnknown when no
// neighbour's variance is known.
PXF_INLINE float kernel_sums_variance(KernelSums s, float factor) {
  return propagated_variance(s.w, s.w2_var_known, s.w2_unknown, s.w_known, s.w_var_known, factor);
}

// The à-trous pass correction c (atrous_variance_correction, exact for a plain convolution) at a
// pixel whose range weights keep the share rho = sum h r / sum h of the pass's kernel: c where
// rho = 1, 1 where only the centre tap counts (its variance is the previous pass's own); in between
// linear, an interpolation fitted rather than derived: it claims a little more than the variance of
// L_f over seeds, where c everywhere would claim several times too much (docs/method.md section 2.3).
PXF_INLINE float atrous_local_correction(float c, float rho) { return 1.0f + (c - 1.0f) * clamp(rho, 0.0f, 1.0f); }

// ---- Perceived variance ----

// var / lb^2 without overflow in the intermediate; 0 when var <= 0, +inf when lb <= 0.
PXF_INLINE float relative_variance(float var, float lb) {
  if (!(var > 0.0f)) return 0.0f;
  if (!(lb > 0.0f)) return kInf;
  return (var / lb) / lb;
}

// Perceived variance u of a pixel whose n >= 2 HV samples were all equal (sample variance exactly
// 0, in practice all zero): that is no evidence of low variance, only that rare paths were missed.
// A mean of L_f is as consistent with such samples as their own mean, so the variance of the mean
// is taken as Y(L_f)^2: u = (Y(L_f) / L_b)^2. Zero where L_f is black (nothing to blend in).
// From kZeroVarianceSamples samples on, the variance taken falls as 1 / n: Y(L_f)^2 k / n is the
// largest variance of the mean that light of mean Y(L_f) can have when it arrives in paths no
// rarer than 1 in k (all of it in paths of probability 1/k, by Cauchy-Schwarz). Without that, a
// pixel whose light truly is 0 beside lit neighbours (cornell: points of the mirror sphere that
// reflect the open front) kept u = (Y(L_f) / L_b)^2 whatever its samples, stayed filtered forever
// and so kept the filter's bias, however many samples it took. 1024: the rarest light the built-in
// scenes are known to need, the mirror sphere's caustic on a wall, comes in about 1 BSDF sample in
// 1000 (docs/guiding.md). n: the pixel's own sample count (pixel_samples); 0 or unknown: no decay.
PXF_CONST float kZeroVarianceSamples = 1024.0f;
PXF_INLINE float zero_variance_u(float y_f, float lb, float n) {
  if (!(y_f > 0.0f)) return 0.0f;
  if (!(lb > 0.0f)) return kInf;
  float r = y_f / lb;
  return n > kZeroVarianceSamples ? r * r * (kZeroVarianceSamples / n) : r * r;
}

// The pixel's own sample count n_p, from the run's count n and the pixel's threshold factor
// (pixel_threshold): n where the factor is 1 (every pixel of a uniform frame), else the count whose
// threshold correction (n_p - 3) / (n_p - 1) is the factor times the run's (n <= 4 counts as 4, as
// effective_threshold does). 0 where n is unknown (0).
PXF_INLINE float pixel_samples(float run_samples, float factor) {
  if (factor == 1.0f || !(run_samples > 4.0f)) return run_samples;
  float g = factor * ((run_samples - 3.0f) / (run_samples - 1.0f));  // (n_p - 3) / (n_p - 1)
  if (!(g < 1.0f)) return kInf;
  return max((3.0f - g) / (1.0f - g), 4.0f);
}

// The least range weight a neighbour's variance is pooled with: the smallest normal float. The
// GPU flushes a smaller weight to 0 (exp(-e) for e > 87), so the shader leaves such a neighbour
// out; the C++ compilation, whose weights are doubles, left it in, and where every known
// neighbour was that far across a range edge it normalized their tiny weights back to a full
// mean: the CPU reference and the explorer's inspector pooled a variance the blend pass did not,
// and so gave such a pixel another s than the pass.
PXF_CONST float kMinPooledWeight = 1.17549435e-38f;

// The pooling's sums over the 8 neighbours of p (the pixel itself left out, so that the split
// decision can pool each half's own estimate, section 3.8) and the pixel's weight with itself.
struct PooledNeighbours {
  wide_float sw, swv;  // sum of the weights and of the weighted variances of the known neighbours
  wide_float centre;   // range_weight of p with itself
};
PXF_SAMPLER_FN PooledNeighbours pooled_neighbours(sampler2D hv, sampler2D guide, sampler2D surface, ivec2 p, float k_c,
                                                  float k_d, float k_n, float k_r) {
  ivec2 size = textureSize(hv, 0);
  vec4 g_p = texelFetch(guide, p, 0);
  vec4 s_p = texelFetch(surface, p, 0);
  PooledNeighbours n;
  n.sw = 0.0f;
  n.swv = 0.0f;
  n.centre = range_weight(g_p, g_p, s_p, s_p, k_c, k_d, k_n, k_r);
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      ivec2 q = p + ivec2(dx, dy);
      if ((dx == 0 && dy == 0) || any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) continue;
      float v = clean_var(texelFetch(hv, q, 0).a);
      if (!(v > 0.0f)) continue;  // unknown, or all samples equal: no evidence
      wide_float w = range_weight(g_p, texelFetch(guide, q, 0), s_p, texelFetch(surface, q, 0), k_c, k_d, k_n, k_r);
      if (!(w >= kMinPooledWeight)) continue;  // across a range edge: as the GPU flushes it
      n.sw += w;
      n.swv += w * v;
    }
  return n;
}

// The pooled variance of a pixel whose own estimate is `own` (cleaned; kVarUnknown: unknown).
PXF_INLINE float pooled_with_own(PooledNeighbours n, float own) {
  if (own < 0.0f) return kVarUnknown;
  wide_float sw = n.sw, swv = n.swv;
  if (own > 0.0f && n.centre >= kMinPooledWeight) {
    sw += n.centre;
    swv += n.centre * wide_float(own);
  }
  return sw > 0.0f ? max(own, float(swv / sw)) : own;
}

// Var[L_u] for the decisions of the blend and the filter's skipping (docs/method.md section 3.3). A
// variance estimated from few samples is itself noisy, and far more often too low than too high:
// path contributions are heavy-tailed, and a pixel that missed the rare bright paths looks quiet
// (dark speckles kept by case 2). So the decision uses the larger of the pixel's own variance and
// the range-weighted mean of the known variances in its 3x3 neighbourhood (the filter's weights).
// Both fall as 1/n, so the bias still vanishes. Returns kVarUnknown where n < 2, and 0 where all
// the pixel's samples were equal and no neighbour variance is known. A neighbour whose range weight
// is below kMinPooledWeight counts as unknown.
PXF_SAMPLER_FN float pooled_var_u(sampler2D hv, sampler2D guide, sampler2D surface, ivec2 p, float k_c, float k_d,
                                   float k_n, float k_r) {
  float own = clean_var(texelFetch(hv, p, 0).a);
  if (own < 0.0f) return kVarUnknown;
  return pooled_with_own(pooled_neighbours(hv, guide, surface, p, k_c, k_d, k_n, k_r), own);
}

// The threshold of pixel p: a run's t (the threshold after the frame count's samples, t_n of
// docs/method.md 3.5) times the factor in the alpha of the pixel's L_lv texel, which is 1 where the
// pixel holds the frame count's samples and, under adaptive sampling, t_{n_p} / t_n for its own
// count n_p (gl/inputs.h). One product: a uniform frame's threshold is t itself, bit for bit.
PXF_INLINE float pixel_threshold(float t, vec4 lv_texel) { return t * lv_texel.a; }

// The filter's case-2 skip (FilterParams::skip_case2, final pass only): the blend's u (pooled
// variance) with the unfiltered background L_b = Y(L_u) + Y(L_lv); a zero variance (all samples
// equal, no neighbour known) is not trusted. The pooled variance is at least the pixel's own, so a
// pixel whose own variance already exceeds t is not skipped without looking at its neighbours: the
// same answer for a fraction of the cost (at low spp nearly every pixel leaves here, and the 3x3
// pooling cost more than a grid slice).
PXF_SAMPLER_FN bool skip_as_case2(sampler2D hv, sampler2D lv, sampler2D guide, sampler2D surface, ivec2 p, float k_c,
                                  float k_d, float k_n, float k_r, float t) {
  vec4 hv_p = texelFetch(hv, p, 0);
  vec4 lv_p = texelFetch(lv, p, 0);
  float lb = max(luminance(clean(vec3(hv_p))) + luminance(clean(vec3(lv_p))), 0.0f);
  float t_p = max(pixel_threshold(t, lv_p), 0.0f);
  float own = clean_var(hv_p.a);
  if (own > 0.0f && relative_variance(own, lb) > t_p) return false;
  float v = pooled_var_u(hv, guide, surface, p, k_c, k_d, k_n, k_r);
  return v > 0.0f && relative_variance(v, lb) <= t_p;
}

// The skip of the split decision (section 3.8): the split blend shows L_u alone where both halves'
// decisions are case 2, each from the other half's variance, so the skip asks both: the pooled
// variance with each half's estimate as the pixel's own, and neither above t (a half with fewer
// than 2 samples is never skipped: its decision is case 4). half_variances: (V_even, V_odd).
PXF_SAMPLER_FN bool skip_as_case2_by_halves(sampler2D hv, sampler2D lv, sampler2D guide, sampler2D surface,
                                            vec2 half_variances, ivec2 p, float k_c, float k_d, float k_n, float k_r,
                                            float t) {
  vec4 lv_p = texelFetch(lv, p, 0);
  float lb = max(luminance(clean(vec3(texelFetch(hv, p, 0)))) + luminance(clean(vec3(lv_p))), 0.0f);
  float t_p = max(pixel_threshold(t, lv_p), 0.0f);
  float v_even = clean_var(half_variances.x), v_odd = clean_var(half_variances.y);
  if (v_even < 0.0f || v_odd < 0.0f) return false;
  if (relative_variance(max(v_even, v_odd), lb) > t_p) return false;  // the pooled variance is no lower
  PooledNeighbours n = pooled_neighbours(hv, guide, surface, p, k_c, k_d, k_n, k_r);
  float pooled_even = pooled_with_own(n, v_even), pooled_odd = pooled_with_own(n, v_odd);
  return pooled_even > 0.0f && pooled_odd > 0.0f && relative_variance(pooled_even, lb) <= t_p &&
         relative_variance(pooled_odd, lb) <= t_p;
}

// The filter's skip as its uniform skip_case2 asks for it: none, by the pixel's own variance
// (skip_as_case2) or by its halves' (skip_as_case2_by_halves, the split decision's).
PXF_CONST int kSkipOff = 0;
PXF_CONST int kSkipOn = 1;
PXF_CONST int kSkipByHalves = 2;
PXF_SAMPLER_FN bool skip_pixel(int mode, sampler2D hv, sampler2D lv, sampler2D guide, sampler2D surface,
                               sampler2D half_variances, ivec2 p, float k_c, float k_d, float k_n, float k_r, float t) {
  if (mode == kSkipByHalves)
    return skip_as_case2_by_halves(hv, lv, guide, surface, vec2(texelFetch(half_variances, p, 0)), p, k_c, k_d, k_n,
                                   k_r, t);
  return mode == kSkipOn && skip_as_case2(hv, lv, guide, surface, p, k_c, k_d, k_n, k_r, t);
}

// ---- Blend factor ----

// The blend case logic (docs/method.md section 3.2) on relative variances u, f (>= 0, may be
// +inf) and threshold t: case 2 (u <= t) first, case 1 (D < 0), else case 3. NaN u or f count as
// +inf, NaN or negative t as 0. D < 0 <=> t < H = u f / (u + f) = lo / (1 + lo / hi), and
// s = f / (u + f) + sqrt((t - H) / (u + f)): no product of two large or two small numbers, so
// nothing overflows or underflows into a wrong case. Returns s; the case goes to blend_case.
PXF_INLINE float blend_factor(float u, float f, float t, PXF_OUT(int) blend_case) {
  if (!(t >= 0.0f)) t = 0.0f;
  if (isnan(u)) u = kInf;
  if (isnan(f)) f = kInf;
  u = max(u, 0.0f);
  f = max(f, 0.0f);
  if (u <= t) {
    blend_case = kCaseUnfiltered;
    return 1.0f;
  }
  float hi = max(u, f), lo = min(u, f);  // hi > t >= 0
  float r = isinf(hi) ? (isinf(lo) ? 1.0f : 0.0f) : lo / hi;
  float harmonic = isinf(lo) ? kInf : lo / (1.0f + r);
  if (t < harmonic) {
    blend_case = kCaseLeastVariance;
    float uh0 = isinf(hi) ? (isinf(u) ? 1.0f : 0.0f) : u / hi;
    float fh0 = isinf(hi) ? (isinf(f) ? 1.0f : 0.0f) : f / hi;
    return fh0 / (uh0 + fh0);
  }
  // The first term is the minimizer of g (g = H <= t there), so an underflowing second term stays
  // under t.
  float uh = isinf(hi) ? (isinf(u) ? 1.0f : 0.0f) : u / hi;
  float fh = isinf(hi) ? (isinf(f) ? 1.0f : 0.0f) : f / hi;
  float q = isinf(hi) ? 0.0f : ((t - harmonic) / hi) / (1.0f + r);
  blend_case = kCaseMixed;
  return clamp(fh / (uh + fh) + sqrt(q), 0.0f, 1.0f);  // uh + fh >= 1
}

// Below this curvature a of g(s) (in units of max(u, f)) g is taken as flat: g(s) = f = u > t.
#ifdef __cplusplus
PXF_CONST wide_float kBlendFlatCurvature = 1e-12;
#else
const float kBlendFlatCurvature = 1e-6;
#endif

// blend_factor with the covariance of L_u and L_f: the filter averages each pixel's own samples
// with normalized centre weight w (0..1), so Cov[L_u, L_f] = w Var[L_u] and the blend's relative
// variance is g(s) = s^2 u + (1-s)^2 f + 2 s (1-s) w u. Case 2 as above; case 1 where t is below
// the minimum of g on [0, 1]: (u f - c^2) / (u + f - 2c) with c = w u (clamped to sqrt(u f),
// Cauchy-Schwarz), or f where that minimum lies at s < 0 (c > f); case 3 the larger root of
// g(s) = t. w <= 0 (or NaN), or u or f infinite: blend_factor. Scaled by hi = max(u, f) > t.
PXF_INLINE float blend_factor_covariance(float u, float f, float t, float w, PXF_OUT(int) blend_case) {
  float plain = blend_factor(u, f, t, blend_case);
  if (!(w > 0.0f) || blend_case == kCaseUnfiltered || isinf(u) || isinf(f) || isnan(u) || isnan(f)) return plain;
  if (!(t >= 0.0f)) t = 0.0f;
  u = max(u, 0.0f);
  f = max(f, 0.0f);
  wide_float hi = wide_float(max(u, f));
  wide_float uh = wide_float(u) / hi, fh = wide_float(f) / hi, th = wide_float(t) / hi;
  wide_float c = min(wide_float(min(w, 1.0f)) * uh, sqrt(uh * fh));
  wide_float a = uh + fh - 2.0f * c;  // >= (sqrt(uh) - sqrt(fh))^2 >= 0
  blend_case = kCaseLeastVariance;
  if (!(a > kBlendFlatCurvature)) return 0.0f;
  // g's minimum lies at s* = (f - c) / a, below 0 where c > f: then the lowest g on [0, 1] is g(0) = f.
  wide_float s_min = (fh - c) / a, g_min = max((uh * fh - c * c) / a, wide_float(0.0f));
  if (th < (s_min >= 0.0f ? g_min : fh)) return float(max(s_min, wide_float(0.0f)));
  blend_case = kCaseMixed;
  return float(clamp(s_min + sqrt((th - g_min) / a), wide_float(0.0f), wide_float(1.0f)));
}

// ---- Bias guard (docs/method.md section 3.7) ----

// The blend picks s from variances alone, as if L_f were unbiased. Where the filter averages light
// across a change the range buffer does not show (a contact shadow, a caustic, the corner of a
// room), E[L_f] differs from E[L_u] and the blended pixel keeps (1 - s) times that bias: an error
// that does not fall with the noise. The guard measures it. d = Y(L_f) - Y(L_u) has mean b (the
// bias) and, where L_f is unbiased, mean 0; its mean over the pixel's 5x5 neighbourhood
// (kBiasGuardRadius) has variance about sum (Var[L_u] + Var[L_f]) / 25^2 (the covariance of L_u
// and L_f left out: the test reads high, so it errs towards finding no bias). All 25 count alike,
// whatever their range colour: a bias is a property of the filter around the pixel, and weighting
// by the range buffer left fewer pixels to the test, which then missed bias it finds otherwise,
// and the error rose. 5x5 rather than 3x3: a steadier decision. With 3x3 a pixel was raised in
// some seeds and not in others, which added variance to the pixels the blend holds at t, pushing
// them above t (docs/notebook/measurements.md, "Bias guard", has the figures).
// The test: the squared mean of d counts as the bias where it exceeds kBiasGuardZ^2 times that
// variance, else no bias (window_bias_squared).
//
// The 5x5 mean misses a bias on one side of a sharp change the filter blurs: next to a focused
// caustic, the contact shadow under the glass sphere takes the caustic's light in L_f (d > 0) while
// the caustic loses it (d < 0), and the two cancel in the mean: those few pixels stay many times too
// bright, seed after seed, and hold much of the filtered image's error (docs/notebook/measurements.md,
// "Half windows").
// So the guard also judges the four half windows that contain the pixel (5 wide and 3 tall below
// and above it, 3 wide and 5 tall left and right of it) at kBiasGuardHalfZ, stricter against the
// more tests, each with its own mean Var[L_u] (the shadow side's variance, not the caustic's), and
// keeps the window that asks for the largest s (consider_window).
// Windows of 5 or 3 pixels average out a bias that changes sign from pixel to pixel: the detail of a
// normal map or of an environment's reflection in a glossy coat, which the filter blurs. So the guard
// judges the pixel alone too, at kBiasGuardPixelZ (docs/notebook/measurements.md, "Pixel window").
PXF_CONST float kBiasGuardZ = 2.0f;
PXF_CONST float kBiasGuardHalfZ = 4.0f;
PXF_CONST float kBiasGuardPixelZ = 2.5f;
PXF_CONST int kBiasGuardRadius = 2;

// What the guard reads from a window (the 5x5 neighbourhood or one of its halves): sums over its
// pixels of what each contributes (bias_guard_texel).
struct BiasGuardSums {
  wide_float d, var_d;  // sum of d and of Var[L_u] + Var[L_f], over the judged neighbours
  int judged;           // neighbours with n >= 2 that the filter did not skip
  wide_float var_u;     // sum of Var[L_u] over the neighbours with n >= 2
  int known;            // their count
};

// One neighbour's part of the sums, packed so that the sums of a window's texels are texels too (the
// blend pass adds them up in a row pass and a column pass of 5 reads each, instead of 25 reads of two
// textures per pixel: on llvmpipe the blend runs on the CPU cores the path tracer needs):
// (d, Var[L_u] + Var[L_f], Var[L_u], judged + 32 known). The bias test leaves out neighbours with
// n < 2 (no variance to judge d against) and those the filter skipped (L_f is L_u there); the
// variance mean only the first. A variance of 0 (all samples equal) counts as Y(L_f)^2 in both,
// as in zero_variance_u.
PXF_CONST float kBiasGuardKnownUnit = 32.0f;  // more than the 25 neighbours: the two counts stay apart
PXF_INLINE vec4 bias_guard_texel_of(vec4 u_q, vec4 f_q) {
  float vu = clean_var(u_q.a);
  if (vu < 0.0f) return vec4(0.0f);  // n < 2
  float y_f = luminance(clean(vec3(f_q)));
  if (vu == 0.0f) vu = y_f * y_f;  // all samples equal: no evidence of low variance
  if (f_q.a < kVarSkippedBelow) return vec4(0.0f, 0.0f, vu, kBiasGuardKnownUnit);  // skipped by the filter
  return vec4(y_f - luminance(clean(vec3(u_q))), vu + max(clean_var(f_q.a), 0.0f), vu, kBiasGuardKnownUnit + 1.0f);
}
PXF_SAMPLER_FN vec4 bias_guard_texel(sampler2D hv, sampler2D filtered, ivec2 q) {
  return bias_guard_texel_of(texelFetch(hv, q, 0), texelFetch(filtered, q, 0));
}

// Unpacks summed bias_guard_texel values.
PXF_INLINE BiasGuardSums bias_guard_sums_of(vec4 sum) {
  BiasGuardSums sums;
  sums.d = wide_float(sum.x);
  sums.var_d = wide_float(sum.y);
  sums.var_u = wide_float(sum.z);
  sums.known = int(floor(sum.w / kBiasGuardKnownUnit + 0.5f / kBiasGuardKnownUnit));
  sums.judged = int(sum.w - kBiasGuardKnownUnit * float(sums.known) + 0.5f);
  return sums;
}

// The packed sums of bias_guard_texel over the pixels p + (dx, dy), lo <= (dx, dy) <= hi, inside
// the image, by their definition (the CPU reference; the GPU adds the same texels in a row pass and
// a column pass).
PXF_SAMPLER_FN vec4 bias_guard_window_sums(sampler2D hv, sampler2D filtered, ivec2 p, ivec2 lo, ivec2 hi) {
  ivec2 size = textureSize(hv, 0);
  wide_float d = 0.0f, var_d = 0.0f, var_u = 0.0f, counts = 0.0f;
  for (int dy = lo.y; dy <= hi.y; ++dy)
    for (int dx = lo.x; dx <= hi.x; ++dx) {
      ivec2 q = p + ivec2(dx, dy);
      if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) continue;
      vec4 c = bias_guard_texel(hv, filtered, q);
      d += wide_float(c.x);
      var_d += wide_float(c.y);
      var_u += wide_float(c.z);
      counts += wide_float(c.w);
    }
  return vec4(float(d), float(var_d), float(var_u), float(counts));
}

// The squared mean of d over a window where it exceeds z^2 times its variance, else 0.
PXF_INLINE float window_bias_squared(BiasGuardSums sums, float z) {
  if (sums.judged == 0) return 0.0f;
  wide_float n = wide_float(sums.judged);
  wide_float mean = sums.d / n, var_mean = sums.var_d / (n * n);
  wide_float b2 = mean * mean;
  return b2 > wide_float(z * z) * var_mean ? float(min(b2, wide_float(kMaxInput))) : 0.0f;
}

// The Var[L_u] the guard trades bias against: the mean of the known variances over the window's
// pixels (for the 5x5 window, all 25 neighbours), whatever their range colour, where that is
// larger than the pixel's own (the blend's u). The guard adds noise where it raises s, so it must
// not take that noise for less than it is; a variance estimated from few heavy-tailed samples is
// low far more often than high, the more so the fewer pixels it pools (with the blend's u alone the
// guard made textured scenes worse; docs/method.md section 3.7).
PXF_INLINE float broad_var_u(BiasGuardSums sums) {
  return sums.known > 0 ? float(min(sums.var_u / wide_float(sums.known), wide_float(kMaxInput))) : 0.0f;
}

// The blend factor of least expected squared error with L_f biased by b (b2 = b^2 / L_b^2, relative
// like u and f; c = w u the covariance): E[(L - E L_u)^2] / L_b^2 = (1-s)^2 (b2 + f) + s^2 u
// + 2 s (1-s) c is least at s = (b2 + f - c) / (b2 + f + u - 2c). The guard never lowers s: it
// returns max(s, that), and the case kCaseBiasGuard where it raised it. b2 = 0 (no bias measured):
// s and the case unchanged.
PXF_INLINE float bias_guard_factor(float s, float u, float f, float w, float b2, PXF_INOUT(int) blend_case) {
  if (!(b2 > 0.0f) || isinf(u) || isnan(u) || isinf(f) || isnan(f)) return s;
  wide_float uu = wide_float(max(u, 0.0f)), ff = wide_float(max(f, 0.0f)), bb = wide_float(b2);
  wide_float c = min(wide_float(clamp(w, 0.0f, 1.0f)) * uu, sqrt(uu * ff));
  wide_float den = bb + ff + uu - 2.0f * c;  // >= b2 > 0 (u + f - 2c >= 0 by Cauchy-Schwarz)
  float best = float(clamp((bb + ff - c) / den, wide_float(0.0f), wide_float(1.0f)));
  if (!(best > s)) return s;
  blend_case = kCaseBiasGuard;
  return best;
}

// What the guard found around a pixel: the squared bias b2 it measured (0: none) and the mean
// Var[L_u] of the window it measured it in, which the bias is traded against (absolute values).
struct BiasGuardEstimate {
  float b2;
  float var_u;
};

// Takes a window's finding where it asks for a larger s than the best so far: for the least-error
// factor b2 / (b2 + u) (f and c aside) that is the larger b2 / var_u, compared crosswise so that a
// window without known variances (var_u 0) wins over any with them.
PXF_INLINE void consider_window(BiasGuardSums sums, float z, PXF_INOUT(BiasGuardEstimate) best) {
  float b2 = window_bias_squared(sums, z);
  if (!(b2 > 0.0f)) return;
  float var_u = broad_var_u(sums);
  if (best.b2 > 0.0f && !(wide_float(b2) * wide_float(best.var_u) > wide_float(best.b2) * wide_float(var_u))) return;
  best.b2 = b2;
  best.var_u = var_u;
}

// The pixel's own window (its bias_guard_texel), its Var[L_u] taken no lower than the mean over the
// 5x5 window's known variances: from few heavy-tailed samples a pixel's variance is low far more
// often than high, and with its own the test fired on the noise at 16 spp and raised s into speckles.
PXF_INLINE BiasGuardSums pixel_window(vec4 pixel, vec4 full) {
  BiasGuardSums own = bias_guard_sums_of(pixel), around = bias_guard_sums_of(full);
  if (own.known > 0 && around.known > 0) {
    wide_float var_f = own.var_d - own.var_u;
    own.var_u = max(own.var_u, around.var_u / wide_float(around.known));
    own.var_d = own.var_u + var_f;
  }
  return own;
}

// The guard's finding from the packed sums (bias_guard_window_sums) of the 5x5 window at
// kBiasGuardZ, of the pixel alone at kBiasGuardPixelZ (pixel_window), and of its four half windows
// at kBiasGuardHalfZ: y from -r to 0 and from 0 to r (all five columns), x from -r to 0 and from 0
// to r (all five rows).
PXF_INLINE BiasGuardEstimate bias_guard_estimate(vec4 full, vec4 low_y, vec4 high_y, vec4 low_x, vec4 high_x,
                                                 vec4 pixel) {
  BiasGuardEstimate best;
  best.b2 = 0.0f;
  best.var_u = 0.0f;
  consider_window(bias_guard_sums_of(full), kBiasGuardZ, best);
  consider_window(pixel_window(pixel, full), kBiasGuardPixelZ, best);
  consider_window(bias_guard_sums_of(low_y), kBiasGuardHalfZ, best);
  consider_window(bias_guard_sums_of(high_y), kBiasGuardHalfZ, best);
  consider_window(bias_guard_sums_of(low_x), kBiasGuardHalfZ, best);
  consider_window(bias_guard_sums_of(high_x), kBiasGuardHalfZ, best);
  return best;
}

// The finding that decides one half of the pixel's samples under the split decision (section
// 3.8): every window holds the pixel, and there it reads the other half (`other`, its
// bias_guard_texel_of) in place of the whole pixel (`own`), so that nothing of the half it
// decides enters the finding.
PXF_INLINE BiasGuardEstimate half_guard_estimate(vec4 full, vec4 low_y, vec4 high_y, vec4 low_x, vec4 high_x,
                                                 vec4 own, vec4 other) {
  vec4 swap = other - own;
  return bias_guard_estimate(full + swap, low_y + swap, high_y + swap, low_x + swap, high_x + swap, other);
}

// The guard's finding at pixel p by the definition of its windows (the CPU reference), the pixel
// itself read as `pixel`: its own bias_guard_texel for the one decision (then nothing is swapped),
// the other half's for one half of the split decision (half_guard_estimate).
PXF_SAMPLER_FN BiasGuardEstimate bias_guard_estimate_at(sampler2D hv, sampler2D filtered, ivec2 p, vec4 pixel) {
  const int r = kBiasGuardRadius;
  return half_guard_estimate(bias_guard_window_sums(hv, filtered, p, ivec2(-r, -r), ivec2(r, r)),
                             bias_guard_window_sums(hv, filtered, p, ivec2(-r, -r), ivec2(r, 0)),
                             bias_guard_window_sums(hv, filtered, p, ivec2(-r, 0), ivec2(r, r)),
                             bias_guard_window_sums(hv, filtered, p, ivec2(-r, -r), ivec2(0, r)),
                             bias_guard_window_sums(hv, filtered, p, ivec2(0, -r), ivec2(r, r)),
                             bias_guard_texel(hv, filtered, p), pixel);
}

// The guard as the blend applies it (blend_pixel): in cases 1 and 3 only, s and the
// case from bias_guard_factor where the estimate holds a bias, traded against the larger of the
// blend's u and the window's mean variance. lb: the blend's L_b; w: the filter's centre weight (0 if
// none).
PXF_INLINE float guarded_blend_factor(BiasGuardEstimate e, float s, float u, float f, float w, float lb,
                                      PXF_INOUT(int) blend_case) {
  if (blend_case != kCaseMixed && blend_case != kCaseLeastVariance) return s;
  if (!(e.b2 > 0.0f)) return s;
  float u_guard = max(u, relative_variance(e.var_u, lb));
  return bias_guard_factor(s, u_guard, f, w, relative_variance(e.b2, lb), blend_case);
}

// ---- The blend's decision per pixel (docs/method.md section 3.2) ----

// Written once for the blend pass (blend.frag), the CPU reference (cpu_blend) and the explorer's
// inspector (BlendPass::inspect), so that what the inspector shows is what made the image.

// One pixel's texels as the blend pass reads them.
struct BlendTexels {
  vec4 hv;               // rgb L_u, a Var[L_u] of the pixel's own samples (kVarUnknown where n < 2)
  vec4 lv;               // rgb L_lv, a the pixel's threshold factor (pixel_threshold)
  vec4 filtered;         // rgb L_f, a Var[L_f] or a sentinel (kVarSkipped: the filter skipped the pixel)
  float guide_distance;  // the range buffer's distance (the background rule)
};

// A blend run's settings: the pass's uniforms.
struct BlendSwitches {
  bool has_filtered;  // an L_f exists; without one every pixel is case 0 (s = 1)
  bool has_guide;     // the range buffer is given: the background rule and the variance pooling apply
  bool bias_guard;    // raise s where L_f is measurably biased (guarded_blend_factor)
  float t;            // the run's threshold t_n; the pixel's own is pixel_threshold(t, lv)
  float samples;      // the run's sample count n (the zero-variance rule's decay); 0: unknown
};

// What the blend reads only where it compares variances (blend_compares_variances): the pooling
// and the guard read whole neighbourhoods, which the pixels settled before need not pay for.
struct BlendVarianceInputs {
  float var_u_pooled;       // pooled_var_u at the pixel; read only with a guide (has_guide)
  float centre_weight;      // the filter's centre weight w; 0 where none is known (no covariance term)
  BiasGuardEstimate guard;  // the guard's finding; read only with bias_guard
};
PXF_INLINE BlendVarianceInputs blend_variance_inputs_none() {
  BlendVarianceInputs v;
  v.var_u_pooled = 0.0f;
  v.centre_weight = 0.0f;
  v.guard.b2 = 0.0f;
  v.guard.var_u = 0.0f;
  return v;
}

// The decision and the values it was made with, for the inspector to show.
struct BlendPixel {
  int blend_case;  // kCase*
  float s;         // the weight of L_u: L = L_lv + s L_u + (1 - s) L_f
  vec3 radiance;   // that L
  float t;         // the pixel's threshold t_n (pixel_threshold)
  float lb;        // L_b = Y(L_f) + Y(L_lv)
  float var_u;     // the Var[L_u] u comes from: pooled with a guide, else the pixel's own
  float u, f;      // u and f relative to L_b; 0 where the case was settled before comparing them
};

// Not a blend case: the variances decide (blend_case_before_variances).
PXF_CONST int kCaseByVariances = -1;

// The cases the blend settles before comparing variances, in its order: no L_f yet (case 0); the
// filter skipped the pixel (case 2); the background rule (kBackgroundDistanceMin, case 2); n < 2,
// the variance unknown (case 4). kCaseByVariances where none applies.
PXF_INLINE int blend_case_before_variances(BlendTexels px, BlendSwitches on) {
  if (!on.has_filtered) return kCaseNoFiltered;
  if (px.filtered.a < kVarSkippedBelow) return kCaseUnfiltered;
  if (on.has_guide && clean(vec3(px.hv)) == vec3(0.0f) && px.guide_distance >= kBackgroundDistanceMin)
    return kCaseUnfiltered;
  if (clean_var(px.hv.a) < 0.0f) return kCaseUnknownVar;
  return kCaseByVariances;
}
PXF_INLINE bool blend_compares_variances(BlendTexels px, BlendSwitches on) {
  return blend_case_before_variances(px, on) == kCaseByVariances;
}

// What blend_pixel reads where it compares variances: the pooling from its neighbour sums
// (pooled_neighbours) and the pixel's own variance, the filter's centre weight (0: none) and the
// guard's finding (b2, var_u).
PXF_INLINE BlendVarianceInputs blend_variance_inputs(BlendTexels px, BlendSwitches on, PooledNeighbours pooled,
                                                     float centre_weight, vec2 guard) {
  BlendVarianceInputs v = blend_variance_inputs_none();
  if (!blend_compares_variances(px, on)) return v;
  if (on.has_guide) v.var_u_pooled = pooled_with_own(pooled, clean_var(px.hv.a));
  v.centre_weight = centre_weight;
  if (on.bias_guard) {
    v.guard.b2 = guard.x;
    v.guard.var_u = guard.y;
  }
  return v;
}

// The blend of one pixel: the case order above, then u from the pooled variance (the pixel's own
// without a guide; zero_variance_u where it is 0), f, the threshold, the covariance through the
// centre weight (blend_factor_covariance) and the bias guard (guarded_blend_factor).
PXF_INLINE BlendPixel blend_pixel(BlendTexels px, BlendSwitches on, BlendVarianceInputs v) {
  vec3 lu = clean(vec3(px.hv));
  vec3 lv = clean(vec3(px.lv));
  vec3 lf = on.has_filtered ? clean(vec3(px.filtered)) : lu;
  BlendPixel b;
  b.t = pixel_threshold(on.t, px.lv);
  b.lb = max(luminance(lf) + luminance(lv), 0.0f);
  b.var_u = on.has_guide ? v.var_u_pooled : clean_var(px.hv.a);
  b.u = 0.0f;
  b.f = 0.0f;
  b.blend_case = blend_case_before_variances(px, on);
  b.s = b.blend_case == kCaseUnknownVar ? 0.0f : 1.0f;
  if (b.blend_case == kCaseByVariances) {
    float var_f = max(clean_var(px.filtered.a), 0.0f);  // unknown (no neighbour's variance known) reads as 0
    b.u = b.var_u > 0.0f ? relative_variance(b.var_u, b.lb) : zero_variance_u(luminance(lf), b.lb, pixel_samples(on.samples, px.lv.a));
    b.f = relative_variance(var_f, b.lb);
    b.s = blend_factor_covariance(b.u, b.f, b.t, v.centre_weight, b.blend_case);
    if (on.bias_guard) b.s = guarded_blend_factor(v.guard, b.s, b.u, b.f, v.centre_weight, b.lb, b.blend_case);
  }
  b.radiance = clean(lv + b.s * lu + (1.0f - b.s) * lf);
  return b;
}

// ---- The split decision (docs/method.md section 3.8) ----

// A decision made from the pixel's own samples correlates with them: a pixel that caught a bright
// path has a large variance and takes L_f, one that missed it looks quiet and keeps its dark L_u,
// and the image darkens. So each half of the samples (even and odd sample index) is blended with
// the weight the other half's variance decides, and the halves are added back with their shares
// (Rousselle et al. 2012 decide each of two buffers from the other's error estimate).
// The halves' texels (Accumulation::hv_halves): halves rgb L_even, a w = n_even / n; variances
// (V_even, V_odd), the whole mean's variance as each half alone estimates it (kVarUnknown: fewer
// than 2 samples in that half).

// Half `which`'s (0 even, 1 odd) mean and its own variance Var[L_h] = V_h / w_h, as the bias guard reads
// a pixel (bias_guard_texel_of); the odd mean is (L_u - w L_even) / (1 - w).
PXF_INLINE vec4 half_texel(vec4 hv, vec4 halves, vec2 variances, int which) {
  float w_even = clamp(halves.a, 0.0f, 1.0f);
  float w = which == 0 ? w_even : 1.0f - w_even;
  vec3 lu = clean(vec3(hv)), le = clean(vec3(halves));
  if (!(w > 0.0f)) return vec4(lu, kVarUnknown);
  vec3 l = which == 0 ? le : clean((lu - w_even * le) / w);
  float v = clean_var(which == 0 ? variances.x : variances.y);
  return vec4(l, v < 0.0f ? kVarUnknown : min(v / w, kMaxInput));
}

// The texels half `which` (0 even, 1 odd) is decided by: the pixel's, with the other half's
// estimate as its variance.
PXF_INLINE BlendTexels decision_texels(BlendTexels px, vec2 variances, int which) {
  BlendTexels d = px;
  d.hv.a = which == 0 ? variances.y : variances.x;
  return d;
}

// The blend of one pixel from its halves: each half's s from blend_pixel with the other half's
// variance as the pixel's own (v_even and v_odd pooled and guarded likewise), then
// L = L_lv + w (s_e L_e + (1 - s_e) L_f) + (1 - w) (s_o L_o + (1 - s_o) L_f)
//   = L_lv + s L_u + (1 - s) L_f + w (s_e - s_o) (L_e - L_u),  s = w s_e + (1 - w) s_o,
// exactly the one-decision blend where the halves agree. The case, u, f and var_u shown are those
// of the half that takes more of L_f.
PXF_INLINE BlendPixel blend_pixel_split(BlendTexels px, vec4 halves, vec2 variances, BlendSwitches on,
                                        BlendVarianceInputs v_even, BlendVarianceInputs v_odd) {
  BlendPixel be = blend_pixel(decision_texels(px, variances, 0), on, v_even);
  BlendPixel bo = blend_pixel(decision_texels(px, variances, 1), on, v_odd);
  float w = clamp(halves.a, 0.0f, 1.0f);
  BlendPixel b = be.s <= bo.s ? be : bo;
  b.s = w * be.s + (1.0f - w) * bo.s;
  vec3 lu = clean(vec3(px.hv)), lv = clean(vec3(px.lv));
  vec3 lf = on.has_filtered ? clean(vec3(px.filtered)) : lu;
  b.radiance = clean(lv + b.s * lu + (1.0f - b.s) * lf + (w * (be.s - bo.s)) * (clean(vec3(halves)) - lu));
  return b;
}

// ---- Albedo demodulation ----

// The albedo divides HV channel by channel: it is the directional albedo of all the non-delta
// lobes (PathSample::albedo), specular included, so no channel of the light those lobes carry is
// much larger than that channel of the albedo, and a saturated texture amplifies nothing. A channel
// below kChannelFloor of the albedo's luminance (a pure-red metal's blue) is floored there.
PXF_CONST float kChannelFloor = 0.05f;
PXF_INLINE vec3 modulation_factor(vec3 albedo) {
  vec3 a = max(clean(albedo), vec3(0.0f));
  return max(a, vec3(kChannelFloor * luminance(a)));
}
// The luminance variance of l * m given that of l: the relative noise is taken as the same in every
// channel, so Var scales with (Y(l m) / Y(l))^2; by Y(m)^2 where l is black (exact for a grey m).
PXF_INLINE float modulated_var(float v, vec3 l, vec3 m) {
  if (!(v >= 0.0f)) return v;  // the sentinels are kept
  float y = luminance(l);
  float r = y > 0.0f ? luminance(l * m) / y : luminance(m);
  return min((v * r) * r, kMaxInput);
}

// The filter's input at p under demodulation: rgb L_u / m, a its luminance variance (modulated_var),
// m = modulation_factor(mean albedo). A pixel whose mean albedo's luminance is below kAlbedoEpsilon
// holds no light to demodulate (its L_u shrinks with its coverage and is about 0), and as a neighbour
// it would pull the light filtered around it toward 0: it takes the mean of its 3x3 neighbours that
// are demodulated, and the mean of their variances (they speak for it).
// None of them: its own L_u and Var[L_u], as without demodulation.
PXF_SAMPLER_FN vec4 demodulated_texel(sampler2D hv, sampler2D albedo, ivec2 p) {
  vec4 own = texelFetch(hv, p, 0);
  vec3 m = modulation_factor(vec3(texelFetch(albedo, p, 0)));
  vec3 l = clean(vec3(own));
  if (luminance(m) >= kAlbedoEpsilon) return vec4(l / m, modulated_var(clean_var(own.a), l, vec3(1.0f) / m));
  ivec2 size = textureSize(hv, 0);
  vec3 sum = vec3(0.0f);
  float count = 0.0f, var_sum = 0.0f, var_count = 0.0f;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      ivec2 q = p + ivec2(dx, dy);
      if (q.x < 0 || q.y < 0 || q.x >= size.x || q.y >= size.y) continue;
      vec3 mq = modulation_factor(vec3(texelFetch(albedo, q, 0)));
      if (!(luminance(mq) >= kAlbedoEpsilon)) continue;
      vec4 texel = texelFetch(hv, q, 0);
      vec3 lq = clean(vec3(texel));
      sum += lq / mq;
      count += 1.0f;
      float vq = modulated_var(clean_var(texel.a), lq, vec3(1.0f) / mq);
      if (vq >= 0.0f) {
        var_sum += vq;
        var_count += 1.0f;
      }
    }
  if (count > 0.0f) return vec4(sum / count, var_count > 0.0f ? var_sum / var_count : kVarUnknown);
  return vec4(l, clean_var(own.a));
}

// The filter's output at p remodulated: rgb m L_f', a its luminance variance (modulated_var), at
// every pixel, down to m = 0. The mean albedo is coverage times albedo, so a pixel that surfaces
// barely cover takes that share of the light filtered around it, and a gap between thin strands,
// which no surface covers, none of it.
PXF_INLINE vec4 remodulated_texel(vec4 filtered, vec3 albedo) {
  vec3 m = modulation_factor(albedo);
  vec3 l = clean(vec3(filtered));
  return vec4(clean(m * l), modulated_var(filtered.a, l, m));
}

// ---- Filter variants ----

// The B3-spline taps of the à-trous kernel; its 5x5 kernel h is their outer product (sum 1).
PXF_CONST float kB3[5] = PXF_FLOAT_ARRAY5(1.0f / 16.0f, 4.0f / 16.0f, 6.0f / 16.0f, 4.0f / 16.0f, 1.0f / 16.0f);

// The subsampled variant's pattern rotation of pixel p: an integer hash (the "lowbias32"
// finalizer) of the pixel, modulo the number of rotations.
PXF_INLINE int subsampled_rotation(ivec2 p, int rotations) {
  uint h = uint(p.x) * 0x8da6b343u ^ uint(p.y) * 0xd8163841u;
  h ^= h >> 16;
  h *= 0x7feb352du;
  h ^= h >> 15;
  h *= 0x846ca68bu;
  h ^= h >> 16;
  return int(h % uint(rotations));
}

// ---- Bilateral grid (cell layout: gl/grid_layout.h) ----

// Range cells along z (see gl/grid_layout.h).
PXF_CONST int kGridRangeCells = 40;
// The grid blur, along each axis in turn: the binomial taps 1/4 [1 2 1] (a variance of 1/2 cell^2;
// Chen et al. blur with a Gaussian of one cell, which needs 5 taps). Taps outside the grid are left
// out.
PXF_CONST int kGridBlurRadius = 1;
PXF_CONST float kGridBlurTaps[3] = PXF_FLOAT_ARRAY3(0.25f, 0.5f, 0.25f);

// The blur tap g(d) along one axis, 0 beyond the taps.
PXF_INLINE float grid_blur_tap(int d) { return abs(d) <= kGridBlurRadius ? kGridBlurTaps[d + kGridBlurRadius] : 0.0f; }

// The range coordinate: luminance of the cleaned range color (a guide texel), negative values read as 0.
PXF_INLINE float guide_luminance(vec4 g) { return max(luminance(clean(vec3(g))), 0.0f); }

// Range cell size from the guide's luminance span [y_min, y_max]: min_cell_z (gl/grid_layout.h:
// grid_min_cell_z), stretched so that the span fits the kGridRangeCells cells (z in [0, nz - 1]).
PXF_INLINE float grid_cell_z(float y_min, float y_max, float min_cell_z) {
  return max(min_cell_z, (y_max - y_min) / float(kGridRangeCells - 1));
}
// z of a luminance: (Y - Y_min) / cell_z, clamped to the grid.
PXF_INLINE float grid_z(float y, float y_min, float cell_z) {
  return clamp((y - y_min) / cell_z, 0.0f, float(kGridRangeCells - 1));
}

// Var[L_f] correction for the interpolation along one spatial axis at fraction a (see
// gl/grid_reference.cpp): the two interpolated cells are correlated (the blur spreads each pixel
// into both), which the squared interpolation weights ignore. With G0 = sum g^2 and G1 =
// sum g(k) g(k+1) of the blur taps (6/16 and 4/16 for 1/4 [1 2 1]), the exact variance over
// uniformly occupied cells is (a0^2 + a1^2) G0 + 2 a0 a1 G1 against (a0^2 + a1^2) G0 propagated.
PXF_INLINE float grid_interpolation_correction(float a) {
  PXF_CONST float g0 = 6.0f / 16.0f, g1 = 4.0f / 16.0f;
  float b = 1.0f - a;
  return 1.0f + 2.0f * a * b * g1 / (g0 * (a * a + b * b));
}

// The same correction along the range axis z, for a pixel at fraction a between range cells k0 and
// k0 + 1 whose own (nearest) cell is `own`. The range neighbours that matter lie in the pixel's own
// cell (a surface of one range colour), so the two interpolated cells hold the same pixels through
// the blur with taps g0 = g(k0 - own), g1 = g(k0 + 1 - own): the exact variance is
// ((1 - a) g0 + a g1)^2 against ((1 - a)^2 g0^2 + a^2 g1^2) propagated (the cells hold g^2 Var).
// 1 at a = 0 and 1; 1.8 at a = 1/2. Without it Var[L_f] falls well short of the variance over
// seeds, most halfway between cells (docs/filter-grid.md, "Var[L_f]").
PXF_INLINE float grid_range_correction(float a, int k0, int own) {
  float w0 = (1.0f - a) * grid_blur_tap(k0 - own), w1 = a * grid_blur_tap(k0 + 1 - own);
  return (w0 + w1) * (w0 + w1) / (w0 * w0 + w1 * w1);  // > 0: own is k0 or k0 + 1, with weight >= 1/2
}

// Nearest cell of a grid coordinate (cell centers at integers).
PXF_INLINE int nearest_cell(float u) { return int(floor(u + 0.5f)); }

PXF_SHARED_END
