#include "gl/cpu_reference.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <mutex>
#include <utility>
#include "gl/grid_reference.h"

namespace pxf {

const std::vector<std::string>& filter_kind_names() {
  static const std::vector<std::string> names = {"bilateral-depth", "bilateral", "separable", "atrous",
                                                         "subsampled", "grid"};
  return names;
}
const char* filter_kind_name(FilterKind kind) {
  return kind == FilterKind::None ? "none" : filter_kind_names()[static_cast<int>(kind)].c_str();
}
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

// The B3-spline taps of the à-trous kernel; the 5x5 kernel h is their outer product (sum 1).
constexpr float kB3[5] = {1.0f / 16, 4.0f / 16, 6.0f / 16, 4.0f / 16, 1.0f / 16};

}  // namespace

// After the first pass, neighbouring outputs share inputs, so propagating Var as if they were
// independent underestimates it (28.8x at sigma_s = 8 for white noise). Where all range weights are
// 1 the passes are plain convolutions with the separable kernel K_k = K_{k-1} * h_k (h_k: B3 taps
// at spacing 2^k), whose exact white-noise variance is (sum K_k^2)^2; the factor is that over
// (sum h^2)^2 times the previous pass's exact variance: 1, 2.73, 3.20, 3.31, 3.33. At range edges
// the correlation is smaller, so the corrected variance errs on the high (safe) side there.
float atrous_variance_correction(int pass) {
  static const std::vector<float> factors = [] {
    std::vector<float> out;
    std::vector<double> kernel = {1.0};
    double h2 = 0, previous = 1.0;
    for (float b : kB3) h2 += double(b) * b;
    for (int k = 0; 2 * ((2 << k) - 1) <= 2 * kMaxFilterRadius; ++k) {
      const int step = 1 << k;
      std::vector<double> next(kernel.size() + 4 * step, 0.0);
      for (size_t i = 0; i < kernel.size(); ++i)
        for (int j = 0; j < 5; ++j) next[i + j * step] += kernel[i] * kB3[j];
      kernel = std::move(next);
      double sum2 = 0;
      for (double v : kernel) sum2 += v * v;
      const double exact = sum2 * sum2;
      out.push_back(static_cast<float>(exact / (previous * h2 * h2)));
      previous = exact;
    }
    return out;
  }();
  return factors[std::clamp<size_t>(static_cast<size_t>(std::max(pass, 0)), 0, factors.size() - 1)];
}

// ---- The subsampled variant's taps ----

namespace {

// A small deterministic generator (the table must not depend on the standard library's
// distributions, which differ between implementations): splitmix64, uniform in [0, 1).
struct TapRng {
  uint64_t state;
  double uniform() {
    uint64_t z = (state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return double((z ^ (z >> 31)) >> 11) * 0x1.0p-53;
  }
};

struct Point {
  double x, y;
};

// `count` points of unit-sigma Gaussian density truncated at radius 3, the first at the origin,
// spread as a Poisson disk whose spacing follows the density: two points a, b are at least
// alpha (r(a) + r(b)) / 2 apart, r(p) = 1 / sqrt(count g(p)) the mean spacing where count points
// have density g. Dart throwing; alpha shrinks when darts keep failing, so it always finishes.
std::vector<Point> poisson_gaussian_pattern(int count) {
  const double kPi = 3.14159265358979323846;
  auto spacing = [count, kPi](const Point& p) {
    const double g = std::exp(-0.5 * (p.x * p.x + p.y * p.y)) / (2 * kPi);
    return 1.0 / std::sqrt(count * g);
  };
  std::vector<Point> points = {{0.0, 0.0}};
  TapRng rng{0x5eed5eedull + static_cast<uint64_t>(count)};
  double alpha = 0.9;
  int failures = 0;
  while (static_cast<int>(points.size()) < count) {
    // Box-Muller, truncated at 3 sigma like the exact kernel's radius.
    const double radius = std::sqrt(-2.0 * std::log(1.0 - rng.uniform())), angle = 2 * kPi * rng.uniform();
    if (radius > 3.0) continue;
    const Point c{radius * std::cos(angle), radius * std::sin(angle)};
    const double rc = spacing(c);
    bool ok = true;
    for (const Point& a : points) {
      const double min_d = alpha * 0.5 * (rc + spacing(a));
      if ((a.x - c.x) * (a.x - c.x) + (a.y - c.y) * (a.y - c.y) < min_d * min_d) {
        ok = false;
        break;
      }
    }
    if (ok) {
      points.push_back(c);
      failures = 0;
    } else if (++failures > 2000) {
      alpha *= 0.95;
      failures = 0;
    }
  }
  return points;
}

const std::vector<Point>& cached_pattern(int count) {
  static std::mutex mutex;
  static std::map<int, std::vector<Point>> patterns;
  std::lock_guard<std::mutex> lock(mutex);
  auto it = patterns.find(count);
  if (it == patterns.end()) it = patterns.emplace(count, poisson_gaussian_pattern(count)).first;
  return it->second;
}

}  // namespace

// The unit pattern scaled by sigma_s, rotated by 2 pi r / kSubsampledRotations for each r, rounded
// to whole pixels; taps that round to the same pixel are merged (their count is the weight factor,
// so Var[L_f] = sum w^2 Var stays exact). sigma_s 0 or invalid: the centre alone.
SubsampledTapTable subsampled_tap_table(float sigma_s, int taps) {
  taps = std::clamp(taps, 1, 1024);
  const double sigma = std::isfinite(sigma_s) && sigma_s > 0 ? std::min<double>(sigma_s, kMaxFilterRadius / 3.0) : 0.0;
  const std::vector<Point>& pattern = cached_pattern(taps);
  std::vector<std::vector<SubsampledTap>> rotations(kSubsampledRotations);
  SubsampledTapTable table;
  for (int r = 0; r < kSubsampledRotations; ++r) {
    const double angle = 2 * 3.14159265358979323846 * r / kSubsampledRotations;
    const double c = std::cos(angle), s = std::sin(angle);
    std::map<std::pair<int, int>, int> counts;
    for (const Point& p : pattern) {
      const int dx = static_cast<int>(std::lround(sigma * (c * p.x - s * p.y)));
      const int dy = static_cast<int>(std::lround(sigma * (s * p.x + c * p.y)));
      ++counts[{std::clamp(dx, -kMaxFilterRadius, kMaxFilterRadius), std::clamp(dy, -kMaxFilterRadius, kMaxFilterRadius)}];
    }
    for (const auto& [offset, n] : counts) rotations[r].push_back({offset.first, offset.second, n, 0});
    table.per_rotation = std::max(table.per_rotation, static_cast<int>(rotations[r].size()));
  }
  for (auto& list : rotations) {
    list.resize(table.per_rotation);  // padded with count 0
    table.taps.insert(table.taps.end(), list.begin(), list.end());
  }
  return table;
}

// An integer hash of the pixel (the "lowbias32" finalizer), the same in shaders/subsampled.frag.
int subsampled_rotation(int x, int y) {
  uint32_t h = static_cast<uint32_t>(x) * 0x8da6b343u ^ static_cast<uint32_t>(y) * 0xd8163841u;
  h ^= h >> 16;
  h *= 0x7feb352du;
  h ^= h >> 15;
  h *= 0x846ca68bu;
  h ^= h >> 16;
  return static_cast<int>(h % kSubsampledRotations);
}

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

}  // namespace

float clean(float v) { return std::isfinite(v) ? std::clamp(v, -kMaxInput, kMaxInput) : 0.0f; }
float clean_var(float v) { return (std::isfinite(v) && v >= 0.0f) ? std::min(v, kMaxInput) : kVarUnknown; }

namespace {

float lum(const float* c) { return luminance(c[0], c[1], c[2]); }

struct Px {
  float c[3];
};
Px rgb_at(const Image& im, int x, int y) {
  return {{clean(im.at(x, y, 0)), clean(im.at(x, y, 1)), clean(im.at(x, y, 2))}};
}
// The exponent of the range weight between pixels p and q (color and depth terms).
double range_exponent(const Image& range_color, const Image& depth, int px, int py, int qx, int qy,
                      const RangeWeights& range) {
  Px rp = rgb_at(range_color, px, py), rq = rgb_at(range_color, qx, qy);
  double dc2 = 0;
  for (int c = 0; c < 3; ++c) dc2 += double(rp.c[c] - rq.c[c]) * (rp.c[c] - rq.c[c]);
  double dd = double(clean(depth.at(px, py, 0))) - clean(depth.at(qx, qy, 0));
  return dc2 * range.k_c + dd * dd * range.k_d;
}

// One pixel's kernel sums: L_f = sum w L / sum w, Var[L_f] = sum w^2 Var / (sum w)^2. Neighbours
// of unknown variance (n < 2, or 0: all samples equal, no evidence) count with the kernel-weighted
// mean of the known ones.
struct KernelSums {
  double w = 0, wl[3] = {0, 0, 0};
  double w2_var_known = 0, w2_unknown = 0, w_known = 0, w_var_known = 0;

  void add(double wq, const Px& l, float var) {
    w += wq;
    for (int c = 0; c < 3; ++c) wl[c] += wq * l.c[c];
    if (var > 0.0f) {
      w2_var_known += wq * wq * var;
      w_known += wq;
      w_var_known += wq * var;
    } else {
      w2_unknown += wq * wq;
    }
  }
  // w > 0: the center tap always has range weight 1.
  void write(FilterOutput& out, int x, int y, float variance_factor = 1.0f) const {
    for (int c = 0; c < 3; ++c) out.filtered.at(x, y, c) = static_cast<float>(wl[c] / w);
    out.variance.at(x, y, 0) =
        w_known > 0 ? static_cast<float>(variance_factor * (w2_var_known + w2_unknown * (w_var_known / w_known)) / (w * w))
                    : kVarUnknown;
    if (!out.centre_weight.pixels.empty()) out.centre_weight.at(x, y, 0) = static_cast<float>(1.0 / w);
  }
};

}  // namespace

bool case2_skip_decision(const Image& hv, const Image& var_u, const Image& lv, const Image& range_color,
                         const Image& depth, const FilterParams& p, float t, int x, int y) {
  const float v = pooled_var_u(var_u, range_color, depth, x, y, range_weights(p));
  const Px lu = rgb_at(hv, x, y), l = rgb_at(lv, x, y);
  const float lb = std::max(lum(lu.c) + lum(l.c), 0.0f);
  return v > 0.0f && relative_variance(v, lb) <= std::max(t, 0.0f);
}

bool skip_as_case2(const Image& hv, const Image& var_u, const Image& lv, const Image& range_color,
                   const Image& depth, const FilterParams& p, float t, int x, int y, FilterOutput& out) {
  if (!case2_skip_decision(hv, var_u, lv, range_color, depth, p, t, x, y)) return false;
  const Px lu = rgb_at(hv, x, y);
  for (int c = 0; c < 3; ++c) out.filtered.at(x, y, c) = lu.c[c];
  out.variance.at(x, y, 0) = kVarSkipped;
  return true;
}

float relative_variance(float var, float lb) {
  if (!(var > 0.0f)) return 0.0f;
  if (!(lb > 0.0f)) return kInf;
  return (var / lb) / lb;
}

float zero_variance_u(float y_f, float lb) {
  if (!(y_f > 0.0f)) return 0.0f;
  if (!(lb > 0.0f)) return kInf;
  const float r = y_f / lb;
  return r * r;
}

float pooled_var_u(const Image& var_u, const Image& range_color, const Image& depth, int x, int y,
                   const RangeWeights& range) {
  const float own = clean_var(var_u.at(x, y, 0));
  if (own < 0.0f) return kVarUnknown;
  double sw = 0, swv = 0;
  for (int qy = std::max(0, y - 1); qy <= std::min(var_u.height - 1, y + 1); ++qy)
    for (int qx = std::max(0, x - 1); qx <= std::min(var_u.width - 1, x + 1); ++qx) {
      const float v = clean_var(var_u.at(qx, qy, 0));
      if (!(v > 0.0f)) continue;
      const double w = std::exp(-range_exponent(range_color, depth, x, y, qx, qy, range));
      sw += w;
      swv += w * v;
    }
  return sw > 0 ? std::max(own, static_cast<float>(swv / sw)) : own;
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

BlendDecision blend_decision(float u, float f, float t, float w) {
  const BlendDecision plain = blend_decision(u, f, t);
  if (!(w > 0.0f) || plain.blend_case == kCaseUnfiltered || !std::isfinite(u) || !std::isfinite(f)) return plain;
  if (!(t >= 0.0f)) t = 0.0f;
  u = std::max(u, 0.0f);
  f = std::max(f, 0.0f);
  // Scaled by hi = max(u, f) > t as above; double keeps the products of the scaled values.
  const double hi = std::max(u, f), uh = u / hi, fh = f / hi, th = t / hi;
  const double c = std::min(static_cast<double>(std::min(w, 1.0f)) * uh, std::sqrt(uh * fh));
  const double a = uh + fh - 2.0 * c;  // >= (sqrt(uh) - sqrt(fh))^2 >= 0
  if (!(a > 1e-12)) return {0.0f, kCaseFilteredOnly};  // g(s) = f = u > t for every s
  // g's minimum lies at s* = (f - c) / a, below 0 where c > f: then the lowest g on [0, 1] is g(0) = f.
  const double s_min = (fh - c) / a, g_min = std::max(0.0, (uh * fh - c * c) / a);
  if (th < (s_min >= 0.0 ? g_min : fh)) return {0.0f, kCaseFilteredOnly};
  const double s = s_min + std::sqrt((th - g_min) / a);
  return {static_cast<float>(std::clamp(s, 0.0, 1.0)), kCaseMixed};
}

namespace {

// One bilateral pass over `signal` (rgb) with variance `signal_var`, kernel extent (ex, ey) times
// the radius; skipping (final pass only) looks at the unfiltered hv / var_u.
FilterOutput filter_once(const Image& signal, const Image& signal_var, const Image& hv, const Image& var_u,
                         const Image& lv, const Image& range_color, const Image& depth, const FilterParams& p,
                         float t, int ex, int ey, bool final_pass) {
  const int w = hv.width, h = hv.height;
  FilterOutput out{Image::rgb(w, h), Image::gray(w, h), Image::gray(w, h, "Y", 1.0f)};
  const int radius = std::min(kMaxFilterRadius, static_cast<int>(std::ceil(3.0f * std::max(p.sigma_s, 0.0f))));
  const float ks = inv_two_sigma2(p.sigma_s);
  const RangeWeights range = range_weights(p);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      if (final_pass && p.skip_case2 && skip_as_case2(hv, var_u, lv, range_color, depth, p, t, x, y, out)) continue;
      KernelSums sums;
      for (int qy = std::max(0, y - radius * ey); qy <= std::min(h - 1, y + radius * ey); ++qy)
        for (int qx = std::max(0, x - radius * ex); qx <= std::min(w - 1, x + radius * ex); ++qx) {
          double e = double((qx - x) * (qx - x) + (qy - y) * (qy - y)) * ks +
                     range_exponent(range_color, depth, x, y, qx, qy, range);
          sums.add(std::exp(-e), rgb_at(signal, qx, qy), clean_var(signal_var.at(qx, qy, 0)));
        }
      sums.write(out, x, y);
    }
  return out;
}

// ---- Edge-avoiding à-trous (FilterKind::Atrous) ----

// One à-trous pass over `signal` (rgb) with variance `signal_var`: the 5x5 taps at hole spacing
// `step`, weighted by h x the range weights (color, depth), taps outside the image left out (the
// sums are normalized). Skipping (final pass only) looks at the unfiltered hv / var_u.
FilterOutput atrous_pass(const Image& signal, const Image& signal_var, const Image& hv, const Image& var_u,
                         const Image& lv, const Image& range_color, const Image& depth, const FilterParams& p,
                         float t, int step, float variance_factor, bool final_pass) {
  const int w = hv.width, h = hv.height;
  FilterOutput out{Image::rgb(w, h), Image::gray(w, h)};
  const RangeWeights range = range_weights(p);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      if (final_pass && p.skip_case2 && skip_as_case2(hv, var_u, lv, range_color, depth, p, t, x, y, out)) continue;
      KernelSums sums;
      for (int j = 0; j < 5; ++j)
        for (int i = 0; i < 5; ++i) {
          const int qx = x + (i - 2) * step, qy = y + (j - 2) * step;
          if (qx < 0 || qx >= w || qy < 0 || qy >= h) continue;
          const double range_weight = std::exp(-range_exponent(range_color, depth, x, y, qx, qy, range));
          sums.add(double(kB3[i]) * kB3[j] * range_weight, rgb_at(signal, qx, qy), clean_var(signal_var.at(qx, qy, 0)));
        }
      sums.write(out, x, y, variance_factor);  // sum w >= h(0,0) = 0.14: the center tap has range weight 1
    }
  return out;
}

// atrous_iterations(sigma_s) passes at spacing 1, 2, 4, ...; each pass is a linear filter of the
// previous pass's output. Its Var[L_f] is propagated as if that output's pixels were independent
// and then multiplied by atrous_variance_correction(pass), which makes it exact where all range
// weights are 1 (Atrous.WhiteNoiseVarianceShrinksBySumOfSquaredWeights in gl/passes_test.cpp).
FilterOutput cpu_atrous(const Image& hv, const Image& var_u, const Image& lv, const Image& range_color,
                        const Image& depth, const FilterParams& p, float t) {
  const int passes = atrous_iterations(p.sigma_s);
  FilterOutput level{hv, var_u};
  for (int i = 0; i < passes; ++i)
    level = atrous_pass(level.filtered, level.variance, hv, var_u, lv, range_color, depth, p, t, 1 << i,
                        atrous_variance_correction(i), i + 1 == passes);
  return level;
}

// ---- Subsampled (FilterKind::Subsampled) ----

// The bilateral-depth kernel at the pixel's rotation of the tap table only: each tap weighted by
// its count x the range weights (the spatial weight is in the tap density), taps outside the image
// left out. Mirrors shaders/subsampled.frag.
FilterOutput cpu_subsampled(const Image& hv, const Image& var_u, const Image& lv, const Image& range_color,
                            const Image& depth, const FilterParams& p, float t) {
  const int w = hv.width, h = hv.height;
  FilterOutput out{Image::rgb(w, h), Image::gray(w, h)};
  const RangeWeights range = range_weights(p);
  const SubsampledTapTable table = subsampled_tap_table(p.sigma_s, p.subsampled_taps > 0 ? p.subsampled_taps : kSubsampledTaps);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      if (p.skip_case2 && skip_as_case2(hv, var_u, lv, range_color, depth, p, t, x, y, out)) continue;
      KernelSums sums;
      const SubsampledTap* taps = &table.taps[static_cast<size_t>(subsampled_rotation(x, y)) * table.per_rotation];
      for (int i = 0; i < table.per_rotation && taps[i].count > 0; ++i) {
        const int qx = x + taps[i].dx, qy = y + taps[i].dy;
        if (qx < 0 || qx >= w || qy < 0 || qy >= h) continue;
        const double weight = taps[i].count * std::exp(-range_exponent(range_color, depth, x, y, qx, qy, range));
        sums.add(weight, rgb_at(hv, qx, qy), clean_var(var_u.at(qx, qy, 0)));
      }
      sums.write(out, x, y);  // sum w >= 1: the centre tap is in every rotation
    }
  return out;
}

}  // namespace

FilterOutput cpu_filter(const Image& hv, const Image& var_u, const Image& lv, const Image& range_color,
                        const Image& depth, const FilterParams& p, float t) {
  if (p.kind == FilterKind::None) throw Error("cpu_filter: filter kind none");
  if (p.kind == FilterKind::Atrous) return cpu_atrous(hv, var_u, lv, range_color, depth, p, t);
  if (p.kind == FilterKind::Subsampled) return cpu_subsampled(hv, var_u, lv, range_color, depth, p, t);
  if (p.kind == FilterKind::Grid) return cpu_grid_filter(hv, var_u, lv, range_color, depth, p, t);
  if (p.kind != FilterKind::Separable) return filter_once(hv, var_u, hv, var_u, lv, range_color, depth, p, t, 1, 1, true);
  FilterOutput rows = filter_once(hv, var_u, hv, var_u, lv, range_color, depth, p, t, 1, 0, false);
  FilterOutput out = filter_once(rows.filtered, rows.variance, hv, var_u, lv, range_color, depth, p, t, 0, 1, true);
  out.centre_weight = Image();  // the second pass's centre weight alone would understate it: none
  return out;
}

BlendOutput cpu_blend(const Image& lv, const Image& hv, const Image& var_u, const FilterOutput* filtered, float t,
                      const BlendParams& params, const Image* range_color, const Image* depth) {
  const bool pool = range_color && depth;
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
        } else if (pool && lu.c[0] == 0.0f && lu.c[1] == 0.0f && lu.c[2] == 0.0f &&
                   depth->at(x, y, 0) >= kBackgroundDistanceMin) {
          d = {1.0f, kCaseUnfiltered};  // the background rule
        } else if (vu < 0.0f) {
          d = {0.0f, kCaseUnknownVar};
        } else {
          float vf = std::max(clean_var(vf_raw), 0.0f);  // unknown Var[L_f] (no neighbour variance known) reads as 0
          float lb = std::max(lum(lf.c) + lum(l.c), 0.0f);
          if (pool) vu = pooled_var_u(var_u, *range_color, *depth, x, y, params.range);
          float u = vu > 0.0f ? relative_variance(vu, lb) : zero_variance_u(lum(lf.c), lb);
          const float w_centre = filtered->centre_weight.pixels.empty() ? 0.0f : filtered->centre_weight.at(x, y, 0);
          d = blend_decision(u, relative_variance(vf, lb), t, w_centre);
        }
      }
      for (int c = 0; c < 3; ++c)
        out.final_rgb.at(x, y, c) = clean(l.c[c] + d.s * lu.c[c] + (1.0f - d.s) * lf.c[c]);
      out.s.at(x, y, 0) = d.s;
      out.blend_case.at(x, y, 0) = static_cast<float>(d.blend_case);
    }
  return out;
}

std::array<float, 3> demodulation_factor(float r, float g, float b) {
  const float k = luminance(clean(r), clean(g), clean(b));
  if (!(k >= kAlbedoEpsilon)) return {1.0f, 1.0f, 1.0f};
  return {k, k, k};
}

DemodulatedInputs cpu_demodulate(const Image& hv, const Image& var_u, const Image& lv, const Image& albedo,
                                 const Image& range_color, const Image& depth, const FilterParams& p, float t) {
  const int w = hv.width, h = hv.height;
  DemodulatedInputs out{Image::rgb(w, h), Image::gray(w, h), Image::rgb(w, h)};
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const auto a = demodulation_factor(albedo.at(x, y, 0), albedo.at(x, y, 1), albedo.at(x, y, 2));
      const float k = luminance(a[0], a[1], a[2]);
      const Px lu = rgb_at(hv, x, y);
      for (int c = 0; c < 3; ++c) out.hv.at(x, y, c) = lu.c[c] / a[c];
      const float v = clean_var(var_u.at(x, y, 0));
      out.var_u.at(x, y, 0) = v >= 0.0f ? (v / k) / k : v;
      const bool skip = p.skip_case2 && case2_skip_decision(hv, var_u, lv, range_color, depth, p, t, x, y);
      for (int c = 0; c < 3; ++c) out.lv.at(x, y, c) = skip ? kMaxInput : -kMaxInput;
    }
  return out;
}

FilterOutput cpu_remodulate(const FilterOutput& filtered, const Image& albedo) {
  FilterOutput out = filtered;
  for (int y = 0; y < albedo.height; ++y)
    for (int x = 0; x < albedo.width; ++x) {
      const auto a = demodulation_factor(albedo.at(x, y, 0), albedo.at(x, y, 1), albedo.at(x, y, 2));
      const float k = luminance(a[0], a[1], a[2]);
      const Px lf = rgb_at(filtered.filtered, x, y);
      for (int c = 0; c < 3; ++c) out.filtered.at(x, y, c) = clean(a[c] * lf.c[c]);
      const float v = filtered.variance.at(x, y, 0);
      out.variance.at(x, y, 0) = v >= 0.0f ? (v * k) * k : v;
    }
  return out;
}

double cpu_log_average(const Image& rgb, float delta) { return log_average_luminance(rgb, delta); }

Image cpu_tonemap(const Image& rgb, const TonemapParams& p) { return tonemap_reinhard(rgb, p); }

}  // namespace pxf
