// Shared helpers of the preview passes. Mirrors gl/cpu_reference.cpp and gl/preview_params.h:
// keep the two in step (the gl_tests compare them).
const float kMaxInput = 1.0e30;
const float kVarUnknown = -1.0;
const float kVarSkipped = -2.0;
const float kInf = uintBitsToFloat(0x7f800000u);
const float kBackgroundDistanceMin = 5.0e3;  // kBackgroundDistanceMin in gl/preview_params.h

float luminance(vec3 c) { return dot(c, vec3(0.2126, 0.7152, 0.0722)); }

// Non-finite -> 0, magnitude clamped (so kernel sums stay finite in float).
float clean(float v) { return (isnan(v) || isinf(v)) ? 0.0 : clamp(v, -kMaxInput, kMaxInput); }
vec3 clean(vec3 c) { return vec3(clean(c.r), clean(c.g), clean(c.b)); }
// Variance channel: negative or non-finite = unknown.
float clean_var(float v) { return (isnan(v) || isinf(v) || v < 0.0) ? kVarUnknown : min(v, kMaxInput); }

// var / lb^2 without overflow in the intermediate; 0 when var <= 0, +inf when lb <= 0.
float relative_variance(float var, float lb) {
  if (!(var > 0.0)) return 0.0;
  if (!(lb > 0.0)) return kInf;
  return (var / lb) / lb;
}

// Range weight of the cross bilateral filter (guide: rgb range color, a distance).
float range_weight(vec4 g_p, vec4 g_q, float k_c, float k_d) {
  vec3 dr = clean(g_p.rgb) - clean(g_q.rgb);
  float dd = clean(g_p.a) - clean(g_q.a);
  return exp(-(dot(dr, dr) * k_c + dd * dd * k_d));
}

// Var[L_u] for the decisions of the blend and the filter's skipping (docs/method.md section 3.3). A variance
// estimated from few samples is itself noisy, and far more often too low than too high: path
// contributions are heavy-tailed, and a pixel that missed the rare bright paths looks quiet (dark
// speckles kept by case 2). So the decision uses the larger of the pixel's own variance and the
// range-weighted mean of the known variances in its 3x3 neighbourhood (the filter's weights). Both
// fall as 1/n, so the bias still vanishes. Returns kVarUnknown where n < 2, and 0 where all the
// pixel's samples were equal and no neighbour variance is known. Mirrors cpu_reference.cpp.
float pooled_var_u(sampler2D hv, sampler2D guide, ivec2 p, float k_c, float k_d) {
  float own = clean_var(texelFetch(hv, p, 0).a);
  if (own < 0.0) return kVarUnknown;
  ivec2 size = textureSize(hv, 0);
  vec4 g_p = texelFetch(guide, p, 0);
  float sw = 0.0, swv = 0.0;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      ivec2 q = p + ivec2(dx, dy);
      if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) continue;
      float v = clean_var(texelFetch(hv, q, 0).a);
      if (!(v > 0.0)) continue;  // unknown, or all samples equal: no evidence
      float w = range_weight(g_p, texelFetch(guide, q, 0), k_c, k_d);
      sw += w;
      swv += w * v;
    }
  return sw > 0.0 ? max(own, swv / sw) : own;
}

// Perceived variance u of a pixel whose n >= 2 HV samples were all equal (sample variance exactly
// 0, in practice all zero): that is no evidence of low variance, only that rare paths were missed.
// A mean of L_f is as consistent with such samples as their own mean, so the variance of the mean
// is taken as Y(L_f)^2: u = (Y(L_f) / L_b)^2. Zero where L_f is black (nothing to blend in).
float zero_variance_u(float y_f, float lb) {
  if (!(y_f > 0.0)) return 0.0;
  if (!(lb > 0.0)) return kInf;
  float r = y_f / lb;
  return r * r;
}

// docs/method.md section 3.2: case 2 (u <= t) first, case 1 (D < 0), else case 3. Same algorithm as
// blend_decision() in gl/cpu_reference.cpp: D < 0 <=> t < H = u f / (u + f) = lo / (1 + lo / hi),
// s = f / (u + f) + sqrt((t - H) / (u + f)), all without overflow or harmful underflow.
float blend_factor(float u, float f, float t, out int blend_case) {
  if (!(t >= 0.0)) t = 0.0;
  if (isnan(u)) u = kInf;
  if (isnan(f)) f = kInf;
  u = max(u, 0.0);
  f = max(f, 0.0);
  if (u <= t) { blend_case = 2; return 1.0; }
  float hi = max(u, f), lo = min(u, f);
  float r = isinf(hi) ? (isinf(lo) ? 1.0 : 0.0) : lo / hi;
  float harmonic = isinf(lo) ? kInf : lo / (1.0 + r);
  if (t < harmonic) { blend_case = 1; return 0.0; }
  float uh = isinf(hi) ? (isinf(u) ? 1.0 : 0.0) : u / hi;
  float fh = isinf(hi) ? (isinf(f) ? 1.0 : 0.0) : f / hi;
  float q = isinf(hi) ? 0.0 : ((t - harmonic) / hi) / (1.0 + r);
  blend_case = 3;
  return clamp(fh / (uh + fh) + sqrt(q), 0.0, 1.0);
}

// blend_factor with the covariance of L_u and L_f, Cov = w Var[L_u] (w: the filter's centre
// weight): g(s) = s^2 u + (1-s)^2 f + 2 s (1-s) w u. Mirrors blend_decision(u, f, t, w) in
// gl/cpu_reference.cpp; w <= 0, or u or f infinite: blend_factor.
float blend_factor_covariance(float u, float f, float t, float w, out int blend_case) {
  float plain = blend_factor(u, f, t, blend_case);
  if (!(w > 0.0) || blend_case == 2 || isinf(u) || isinf(f) || isnan(u) || isnan(f)) return plain;
  if (!(t >= 0.0)) t = 0.0;
  u = max(u, 0.0);
  f = max(f, 0.0);
  float hi = max(u, f), uh = u / hi, fh = f / hi, th = t / hi;
  float c = min(min(w, 1.0) * uh, sqrt(uh * fh));
  float a = uh + fh - 2.0 * c;
  blend_case = 1;
  if (!(a > 1e-6)) return 0.0;
  float s_min = (fh - c) / a, g_min = max((uh * fh - c * c) / a, 0.0);
  if (th < (s_min >= 0.0 ? g_min : fh)) return 0.0;
  blend_case = 3;
  return clamp(s_min + sqrt((th - g_min) / a), 0.0, 1.0);
}

// The filter's case-2 skip (FilterParams::skip_case2, final pass only): the blend's u (pooled
// variance) with the unfiltered background; a zero variance (all samples equal, no neighbour known)
// is not trusted. Mirrors skip_as_case2() in gl/cpu_reference.cpp.
// The pooled variance is at least the pixel's own, so a pixel whose own variance already exceeds
// t is not skipped without looking at its neighbours: the same answer for a fraction of the cost
// (at low spp nearly every pixel leaves here, and the 3x3 pooling cost more than a grid slice).
bool skip_as_case2(sampler2D hv, sampler2D lv, sampler2D guide, ivec2 p, float k_c, float k_d, float t) {
  vec4 hv_p = texelFetch(hv, p, 0);
  float lb = max(luminance(clean(hv_p.rgb)) + luminance(clean(texelFetch(lv, p, 0).rgb)), 0.0);
  float own = clean_var(hv_p.a);
  if (own > 0.0 && relative_variance(own, lb) > max(t, 0.0)) return false;
  float v = pooled_var_u(hv, guide, p, k_c, k_d);
  return v > 0.0 && relative_variance(v, lb) <= max(t, 0.0);
}

// Albedo demodulation (gl/demodulation.h): the factor HV is divided by before the filter and L_f
// multiplied by after it: grey, the luminance Y(a) of the pixel's mean albedo where it is at least
// kAlbedoEpsilon, else 1 (a nearly black albedo is not demodulated). Grey, not per channel: a
// channel near 0 (a saturated texture) would amplify that channel of light the albedo does not
// shape (specular highlights, neighbours' light) many times over. Mirrors demodulation_factor()
// in cpu_reference.cpp.
const float kAlbedoEpsilon = 0.05;
vec3 demodulation_factor(vec3 albedo) {
  float k = luminance(clean(albedo));
  return k >= kAlbedoEpsilon ? vec3(k) : vec3(1.0);
}
