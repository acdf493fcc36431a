#include "gl/cpu_reference.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pxf {

const std::vector<std::string>& filter_kind_names() {
  static const std::vector<std::string> names = {"bilateral-depth", "bilateral", "separable", "atrous"};
  return names;
}
const char* filter_kind_name(FilterKind kind) { return filter_kind_names()[static_cast<int>(kind)].c_str(); }
FilterKind parse_filter_kind(const std::string& name) {
  const auto& names = filter_kind_names();
  std::string expected;
  for (size_t i = 0; i < names.size(); ++i) {
    if (names[i] == name) return static_cast<FilterKind>(i);
    expected += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + names[i];
  }
  throw Error("unknown filter '" + name + "' (expected " + expected + ")");
}

// Pass i of the à-trous filter convolves with the B3 spline at hole spacing 2^i, whose variance is
// 4^i px^2 per axis (the taps 1/16 [1 4 6 4 1] have variance 1 at spacing 1), and the variances
// of successive convolutions add: k passes have (4^k - 1) / 3. Passes are added while that is
// below the Gaussian's sigma_s^2 (sigma_s = 8: 4 passes, variance 85 = (9.2 px)^2, footprint
// radius 30 px against the exact kernel's 24), as long as the footprint radius 2 (2^k - 1) of the
// next count fits kMaxFilterRadius (at most 5 passes).
int atrous_iterations(float sigma_s) {
  const double target = double(sigma_s) * sigma_s;
  int passes = 1;
  double variance = 1.0;
  while (variance < target && 2 * ((2 << passes) - 1) <= kMaxFilterRadius) {
    variance += std::ldexp(1.0, 2 * passes);  // pass number `passes` (from 0) adds 4^passes
    ++passes;
  }
  return passes;
}

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// The shaders' sanitize(): non-finite -> 0, magnitude clamped.
float clean(float v) { return std::isfinite(v) ? std::clamp(v, -kMaxInput, kMaxInput) : 0.0f; }
// Variance channel: negative or non-finite = unknown.
float clean_var(float v) { return (std::isfinite(v) && v >= 0.0f) ? std::min(v, kMaxInput) : kVarUnknown; }
float lum(const float* c) { return luminance(c[0], c[1], c[2]); }
float inv_two_sigma2(float sigma) {
  float s = std::max(sigma, 1.0e-6f);
  return 1.0f / (2.0f * s * s);
}

struct Px {
  float c[3];
};
Px rgb_at(const Image& im, int x, int y) {
  return {{clean(im.at(x, y, 0)), clean(im.at(x, y, 1)), clean(im.at(x, y, 2))}};
}

}  // namespace

float relative_variance(float var, float lb) {
  if (!(var > 0.0f)) return 0.0f;
  if (!(lb > 0.0f)) return kInf;
  return (var / lb) / lb;
}

BlendDecision blend_decision(float u, float f, float t) {
  if (!(t >= 0.0f)) t = 0.0f;
  if (std::isnan(u)) u = kInf;
  if (std::isnan(f)) f = kInf;
  u = std::max(u, 0.0f);
  f = std::max(f, 0.0f);
  if (u <= t) return {1.0f, kCaseUnfiltered};
  // D = t u + t f - u f < 0  <=>  t < H = u f / (u + f) = lo / (1 + lo / hi): no product of two
  // large or two small numbers, so nothing overflows or underflows into a wrong case.
  const float hi = std::max(u, f), lo = std::min(u, f);  // hi > t >= 0
  const float r = std::isinf(hi) ? (std::isinf(lo) ? 1.0f : 0.0f) : lo / hi;
  const float harmonic = std::isinf(lo) ? kInf : lo / (1.0f + r);
  if (t < harmonic) return {0.0f, kCaseFilteredOnly};
  // s = (f + sqrt(D)) / (u + f) = f / (u + f) + sqrt((t - H) / (u + f)). The first term is the
  // minimizer of g (g = H <= t there), so an underflowing second term stays under t.
  const float uh = std::isinf(hi) ? (std::isinf(u) ? 1.0f : 0.0f) : u / hi;
  const float fh = std::isinf(hi) ? (std::isinf(f) ? 1.0f : 0.0f) : f / hi;
  const float q = std::isinf(hi) ? 0.0f : ((t - harmonic) / hi) / (1.0f + r);
  const float s = fh / (uh + fh) + std::sqrt(q);  // uh + fh >= 1
  return {std::clamp(s, 0.0f, 1.0f), kCaseMixed};
}

namespace {

// One bilateral pass over `signal` (rgb) with variance `signal_var`, kernel extent (ex, ey) times
// the radius; skipping (final pass only) looks at the unfiltered hv / var_u.
FilterOutput filter_once(const Image& signal, const Image& signal_var, const Image& hv, const Image& var_u,
                         const Image& lv, const Image& range_color, const Image& depth, const FilterParams& p,
                         int ex, int ey, bool final_pass) {
  const int w = hv.width, h = hv.height;
  FilterOutput out{Image::rgb(w, h), Image::gray(w, h)};
  const int radius = std::min(kMaxFilterRadius, static_cast<int>(std::ceil(3.0f * std::max(p.sigma_s, 0.0f))));
  const float ks = inv_two_sigma2(p.sigma_s), kc = inv_two_sigma2(p.sigma_c);
  const float kd = p.kind != FilterKind::Bilateral ? inv_two_sigma2(p.sigma_d) : 0.0f;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      Px lu = rgb_at(hv, x, y);
      float v = clean_var(var_u.at(x, y, 0));
      if (final_pass && p.skip_case2 && v >= 0.0f) {
        Px l = rgb_at(lv, x, y);
        float lb = std::max(lum(lu.c) + lum(l.c), 0.0f);
        if (relative_variance(v, lb) <= std::max(p.t, 0.0f)) {
          for (int c = 0; c < 3; ++c) out.filtered.at(x, y, c) = lu.c[c];
          out.variance.at(x, y, 0) = kVarSkipped;
          continue;
        }
      }
      Px rp = rgb_at(range_color, x, y);
      float dp = clean(depth.at(x, y, 0));
      double sw = 0, swl[3] = {0, 0, 0}, sw2v = 0, sw2u = 0, swk = 0, swv = 0;
      for (int qy = std::max(0, y - radius * ey); qy <= std::min(h - 1, y + radius * ey); ++qy)
        for (int qx = std::max(0, x - radius * ex); qx <= std::min(w - 1, x + radius * ex); ++qx) {
          Px rq = rgb_at(range_color, qx, qy);
          float dq = clean(depth.at(qx, qy, 0));
          double dc2 = 0;
          for (int c = 0; c < 3; ++c) dc2 += double(rp.c[c] - rq.c[c]) * (rp.c[c] - rq.c[c]);
          double dd = double(dp) - dq;
          double e = double((qx - x) * (qx - x) + (qy - y) * (qy - y)) * ks + dc2 * kc + dd * dd * kd;
          double wq = std::exp(-e);
          Px lq = rgb_at(signal, qx, qy);
          float vq = clean_var(signal_var.at(qx, qy, 0));
          sw += wq;
          for (int c = 0; c < 3; ++c) swl[c] += wq * lq.c[c];
          if (vq >= 0.0f) {
            sw2v += wq * wq * vq;
            swk += wq;
            swv += wq * vq;
          } else {
            sw2u += wq * wq;
          }
        }
      // sw >= 1: the center pixel has weight exp(0).
      for (int c = 0; c < 3; ++c) out.filtered.at(x, y, c) = static_cast<float>(swl[c] / sw);
      // Neighbours of unknown variance (n < 2) count with the kernel-weighted mean of the known ones.
      out.variance.at(x, y, 0) =
          swk > 0 ? static_cast<float>((sw2v + sw2u * (swv / swk)) / (sw * sw)) : kVarUnknown;
    }
  return out;
}

// ---- Edge-avoiding à-trous (FilterKind::Atrous) ----

// The B3-spline taps of the à-trous kernel; the 5x5 kernel h is their outer product (sum 1).
constexpr float kB3[5] = {1.0f / 16, 4.0f / 16, 6.0f / 16, 4.0f / 16, 1.0f / 16};

// A variance as the à-trous filter's evidence: unknown when negative or non-finite (n < 2), and
// also when exactly 0: n >= 2 identical samples (typically all zero) are no evidence of low variance.
float evidence_var(float v) {
  const float known = clean_var(v);
  return known > 0.0f ? known : kVarUnknown;
}

// Case 2 with the unfiltered background (FilterParams::skip_case2); unknown variance is never skipped.
bool in_case2(const Px& lu, float var, const Px& lv, float t) {
  if (var < 0.0f) return false;
  const float lb = std::max(lum(lu.c) + lum(lv.c), 0.0f);
  return relative_variance(var, lb) <= std::max(t, 0.0f);
}

// One pixel's kernel sums: L_f = sum w L / sum w, Var[L_f] = sum w^2 Var / (sum w)^2, where
// neighbours of unknown variance count with the kernel-weighted mean of the known ones.
struct KernelSums {
  double w = 0, wl[3] = {0, 0, 0};
  double w2_var_known = 0, w2_unknown = 0, w_known = 0, w_var_known = 0;

  void add(double wq, const Px& l, float var) {
    w += wq;
    for (int c = 0; c < 3; ++c) wl[c] += wq * l.c[c];
    if (var >= 0.0f) {
      w2_var_known += wq * wq * var;
      w_known += wq;
      w_var_known += wq * var;
    } else {
      w2_unknown += wq * wq;
    }
  }
  void write(FilterOutput& out, int x, int y) const {
    for (int c = 0; c < 3; ++c) out.filtered.at(x, y, c) = static_cast<float>(wl[c] / w);
    out.variance.at(x, y, 0) = w_known > 0
                                   ? static_cast<float>((w2_var_known + w2_unknown * (w_var_known / w_known)) / (w * w))
                                   : kVarUnknown;
  }
};

// One à-trous pass over `signal` (rgb) with variance `signal_var`: the 5x5 taps at hole spacing
// `step`, weighted by h x the range weights (color, depth), taps outside the image left out (the
// sums are normalized). Skipping (final pass only) looks at the unfiltered hv / var_u.
FilterOutput atrous_pass(const Image& signal, const Image& signal_var, const Image& hv, const Image& var_u,
                         const Image& lv, const Image& range_color, const Image& depth, const FilterParams& p,
                         int step, bool final_pass) {
  const int w = hv.width, h = hv.height;
  FilterOutput out{Image::rgb(w, h), Image::gray(w, h)};
  const float kc = inv_two_sigma2(p.sigma_c), kd = inv_two_sigma2(p.sigma_d);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      if (final_pass && p.skip_case2) {
        const Px lu = rgb_at(hv, x, y);
        if (in_case2(lu, evidence_var(var_u.at(x, y, 0)), rgb_at(lv, x, y), p.t)) {
          for (int c = 0; c < 3; ++c) out.filtered.at(x, y, c) = lu.c[c];
          out.variance.at(x, y, 0) = kVarSkipped;
          continue;
        }
      }
      const Px rp = rgb_at(range_color, x, y);
      const float dp = clean(depth.at(x, y, 0));
      KernelSums sums;
      for (int j = 0; j < 5; ++j)
        for (int i = 0; i < 5; ++i) {
          const int qx = x + (i - 2) * step, qy = y + (j - 2) * step;
          if (qx < 0 || qx >= w || qy < 0 || qy >= h) continue;
          const Px rq = rgb_at(range_color, qx, qy);
          double dc2 = 0;
          for (int c = 0; c < 3; ++c) dc2 += double(rp.c[c] - rq.c[c]) * (rp.c[c] - rq.c[c]);
          const double dd = double(dp) - clean(depth.at(qx, qy, 0));
          const double range_weight = std::exp(-(dc2 * kc + dd * dd * kd));
          sums.add(double(kB3[i]) * kB3[j] * range_weight, rgb_at(signal, qx, qy), evidence_var(signal_var.at(qx, qy, 0)));
        }
      sums.write(out, x, y);  // sum w >= h(0,0) = 0.14: the center tap has range weight 1
    }
  return out;
}

// atrous_iterations(sigma_s) passes at spacing 1, 2, 4, ...; each pass is a linear filter of the
// previous pass's output, and its Var[L_f] is propagated treating that output's pixels as
// independent. They are not (neighbouring outputs share inputs, positively weighted), so from the
// second pass on Var[L_f] is a lower bound of the true variance of what is computed
// (Atrous.WhiteNoiseVarianceShrinksBySumOfSquaredWeights in gl/passes_test.cpp measures by how
// much: 28.8x below at sigma_s = 8).
FilterOutput cpu_atrous(const Image& hv, const Image& var_u, const Image& lv, const Image& range_color,
                        const Image& depth, const FilterParams& p) {
  const int passes = atrous_iterations(p.sigma_s);
  FilterOutput level{hv, var_u};
  for (int i = 0; i < passes; ++i)
    level = atrous_pass(level.filtered, level.variance, hv, var_u, lv, range_color, depth, p, 1 << i, i + 1 == passes);
  return level;
}

}  // namespace

FilterOutput cpu_filter(const Image& hv, const Image& var_u, const Image& lv, const Image& range_color,
                        const Image& depth, const FilterParams& p) {
  if (p.kind == FilterKind::Atrous) return cpu_atrous(hv, var_u, lv, range_color, depth, p);
  if (p.kind != FilterKind::Separable) return filter_once(hv, var_u, hv, var_u, lv, range_color, depth, p, 1, 1, true);
  FilterOutput rows = filter_once(hv, var_u, hv, var_u, lv, range_color, depth, p, 1, 0, false);
  return filter_once(rows.filtered, rows.variance, hv, var_u, lv, range_color, depth, p, 0, 1, true);
}

BlendOutput cpu_blend(const Image& lv, const Image& hv, const Image& var_u, const FilterOutput* filtered,
                      const BlendParams& params) {
  const int w = hv.width, h = hv.height;
  BlendOutput out{Image::rgb(w, h), Image::gray(w, h), Image::gray(w, h)};
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      Px l = rgb_at(lv, x, y), lu = rgb_at(hv, x, y);
      Px lf = lu;
      BlendDecision d{1.0f, kCaseNoFiltered};
      if (filtered) {
        lf = rgb_at(filtered->filtered, x, y);
        float vf_raw = filtered->variance.at(x, y, 0);
        float vu = clean_var(var_u.at(x, y, 0));
        if (vf_raw < -1.5f) {
          d = {1.0f, kCaseUnfiltered};
        } else if (vu < 0.0f) {
          d = {0.0f, kCaseUnknownVar};
        } else {
          float vf = std::max(clean_var(vf_raw), 0.0f);  // unknown Var[L_f] (unreachable) reads as 0
          float lb = std::max(lum(lf.c) + lum(l.c), 0.0f);
          d = blend_decision(relative_variance(vu, lb), relative_variance(vf, lb), params.t);
        }
      }
      for (int c = 0; c < 3; ++c)
        out.final_rgb.at(x, y, c) = clean(l.c[c] + d.s * lu.c[c] + (1.0f - d.s) * lf.c[c]);
      out.s.at(x, y, 0) = d.s;
      out.blend_case.at(x, y, 0) = static_cast<float>(d.blend_case);
    }
  return out;
}

namespace {
float sanitize_display(float v) { return std::isfinite(v) ? std::clamp(v, 0.0f, kMaxInput) : 0.0f; }
}  // namespace

double cpu_log_average(const Image& rgb, float delta) {
  double sum = 0;
  for (int y = 0; y < rgb.height; ++y)
    for (int x = 0; x < rgb.width; ++x) {
      float c[3] = {sanitize_display(rgb.at(x, y, 0)), sanitize_display(rgb.at(x, y, 1)),
                    sanitize_display(rgb.at(x, y, 2))};
      sum += std::log(double(delta) + lum(c));
    }
  return std::exp(sum / std::max<size_t>(rgb.pixel_count(), 1));
}

Image cpu_tonemap(const Image& rgb, const TonemapParams& p) {
  Image out = Image::rgb(rgb.width, rgb.height);
  double lavg = p.log_average > 0 ? p.log_average : cpu_log_average(rgb, p.delta);
  float k = static_cast<float>(p.key / std::max(lavg, 1e-30));
  for (int y = 0; y < rgb.height; ++y)
    for (int x = 0; x < rgb.width; ++x) {
      float c[3] = {sanitize_display(rgb.at(x, y, 0)), sanitize_display(rgb.at(x, y, 1)),
                    sanitize_display(rgb.at(x, y, 2))};
      float lm = k * lum(c);
      // Ld / Y without dividing by Y: k (1 + Lm / white^2) / (1 + Lm).
      float burn = p.white > 0 ? 1.0f + lm / (p.white * p.white) : 1.0f;
      float scale = k * burn / (1.0f + lm);
      for (int i = 0; i < 3; ++i) out.at(x, y, i) = srgb_from_linear(std::clamp(c[i] * scale, 0.0f, 1.0f));
    }
  return out;
}

}  // namespace pxf
