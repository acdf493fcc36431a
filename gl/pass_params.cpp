#include "gl/pass_params.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <mutex>
#include <utility>
#include "image/image.h"

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

// t (n - 3) / (n - 1): the Jensen excess of a variance from n Gaussian samples removed in
// expectation (docs/method.md 3.5); n below 4 counts as 4.
float effective_threshold(float t, uint64_t samples) {
  const double n = static_cast<double>(std::max<uint64_t>(samples, 4));
  return static_cast<float>(t * ((n - 3.0) / (n - 1.0)));
}

float noise_sigma_s(float sigma_s, uint64_t samples, std::vector<float>& needed) {
  if (samples <= kSigmaShrinkFromSpp || !(sigma_s > kSigmaShrinkMin)) return sigma_s;
  if (needed.empty()) return kSigmaShrinkMin;
  const size_t k = std::min(needed.size() - 1, static_cast<size_t>(kSigmaNoiseQuantile * double(needed.size())));
  std::nth_element(needed.begin(), needed.begin() + static_cast<ptrdiff_t>(k), needed.end());
  const double wanted = std::sqrt(double(needed[k]) / (4.0 * 3.14159265358979323846));
  if (!(wanted < sigma_s)) return sigma_s;  // a NaN or infinite ratio too: the full kernel
  return static_cast<float>(std::max(wanted, double(kSigmaShrinkMin)));
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

// After the first pass, neighbouring outputs share inputs, so propagating Var as if they were
// independent underestimates it (28.8x at sigma_s = 8 for white noise). Where all range weights are
// 1 the passes are plain convolutions with the separable kernel K_k = K_{k-1} * h_k (h_k: B3 taps
// at spacing 2^k), whose exact white-noise variance is (sum K_k^2)^2; the factor is that over
// (sum h^2)^2 times the previous pass's exact variance: 1, 2.73, 3.20, 3.31, 3.33. Where range
// weights are below 1 the correlation is smaller: the passes scale the factor by the share of the
// kernel the range weights keep (shared::atrous_local_correction).
float atrous_variance_correction(int pass) {
  static const std::vector<float> factors = [] {
    std::vector<float> out;
    std::vector<double> kernel = {1.0};
    double h2 = 0, previous = 1.0;
    for (float b : shared::kB3) h2 += double(b) * b;
    for (int k = 0; 2 * ((2 << k) - 1) <= 2 * kMaxFilterRadius; ++k) {
      const int step = 1 << k;
      std::vector<double> next(kernel.size() + 4 * step, 0.0);
      for (size_t i = 0; i < kernel.size(); ++i)
        for (int j = 0; j < 5; ++j) next[i + j * step] += kernel[i] * shared::kB3[j];
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

}  // namespace pxf
