// Shared helpers of the preview passes. Mirrors gl/cpu_reference.cpp and gl/preview_params.h:
// keep the two in step (the gl_tests compare them).
const float kMaxInput = 1.0e30;
const float kVarUnknown = -1.0;
const float kVarSkipped = -2.0;
const float kInf = uintBitsToFloat(0x7f800000u);

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

// SPEC 3.4: case 2 (u <= t) first, case 1 (D < 0), else case 3. Same algorithm as
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

// A variance as the à-trous filter's evidence: unknown when negative or non-finite (n < 2), and
// also when exactly 0: n >= 2 identical samples (typically all zero) are no evidence of low variance.
float evidence_var(float v) {
  float known = clean_var(v);
  return known > 0.0 ? known : kVarUnknown;
}

// Case 2 with the unfiltered background (FilterParams::skip_case2); unknown variance is never skipped.
bool in_case2(vec3 lu, float var, vec3 lv, float t) {
  if (var < 0.0) return false;
  float lb = max(luminance(lu) + luminance(lv), 0.0);
  return relative_variance(var, lb) <= max(t, 0.0);
}
