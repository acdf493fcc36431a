// Sampling building blocks: orthonormal frames, warps from [0,1)^2, MIS heuristics and piecewise
// constant 1D/2D distributions (light selection, environment importance sampling).
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>
#include <glm/glm.hpp>

namespace pxf {

constexpr float kPi = 3.14159265358979323846f;
constexpr float kInvPi = 0.31830988618379067154f;

// An orthonormal basis around a unit normal (Duff et al. 2017, branchless, no singularity).
struct Frame {
  glm::vec3 t, b, n;
  static Frame from_normal(glm::vec3 n) {
    float sign = std::copysign(1.0f, n.z);
    float a = -1.0f / (sign + n.z);
    float bb = n.x * n.y * a;
    Frame f;
    f.n = n;
    f.t = glm::vec3(1.0f + sign * n.x * n.x * a, sign * bb, -sign * n.x);
    f.b = glm::vec3(bb, sign + n.y * n.y * a, -n.y);
    return f;
  }
  glm::vec3 to_local(glm::vec3 v) const { return glm::vec3(glm::dot(v, t), glm::dot(v, b), glm::dot(v, n)); }
  glm::vec3 to_world(glm::vec3 v) const { return t * v.x + b * v.y + n * v.z; }
};

inline glm::vec2 sample_concentric_disk(glm::vec2 u) {
  float x = 2.0f * u.x - 1.0f, y = 2.0f * u.y - 1.0f;
  if (x == 0.0f && y == 0.0f) return glm::vec2(0.0f);
  float r, phi;
  if (std::abs(x) > std::abs(y)) {
    r = x;
    phi = (kPi / 4.0f) * (y / x);
  } else {
    r = y;
    phi = (kPi / 2.0f) - (kPi / 4.0f) * (x / y);
  }
  return glm::vec2(r * std::cos(phi), r * std::sin(phi));
}

// Cosine-weighted hemisphere around +z; pdf = cos(theta) / pi.
inline glm::vec3 sample_cosine_hemisphere(glm::vec2 u) {
  glm::vec2 d = sample_concentric_disk(u);
  float z = std::sqrt(std::max(0.0f, 1.0f - d.x * d.x - d.y * d.y));
  return glm::vec3(d.x, d.y, z);
}

// Uniform on the unit sphere; pdf = 1 / (4 pi).
inline glm::vec3 sample_uniform_sphere(glm::vec2 u) {
  float z = 1.0f - 2.0f * u.x;
  float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
  float phi = 2.0f * kPi * u.y;
  return glm::vec3(r * std::cos(phi), r * std::sin(phi), z);
}

// Uniform barycentrics (b1, b2) on a triangle (b0 = 1 - b1 - b2).
inline glm::vec2 sample_triangle_barycentrics(glm::vec2 u) {
  float s = std::sqrt(u.x);
  return glm::vec2(1.0f - s, u.y * s);
}

// Uniform sampling of the solid angle a rectangle subtends from a point (Ureña, Fajardo and King
// 2013, "An Area-Preserving Parametrization for Spherical Rectangles", as in pbrt-v4): for a light
// that is large or near, area sampling's density varies with cos / r^2 over it and solid-angle
// sampling removes that variance. The map from [0,1)^2 is continuous, so strata stay strata.
class SphericalRectangle {
 public:
  // Corner, perpendicular edges, the viewing point. False when the rectangle is degenerate or has
  // (nearly) no solid angle from `from` (edge-on); then there is nothing to sample this way.
  bool init(glm::vec3 from, glm::vec3 corner, glm::vec3 edge_x, glm::vec3 edge_y) {
    const float lx = glm::length(edge_x), ly = glm::length(edge_y);
    if (!(lx > 0.0f) || !(ly > 0.0f)) return false;
    from_ = from;
    x_ = edge_x / lx;
    y_ = edge_y / ly;
    z_ = glm::cross(x_, y_);
    const glm::vec3 d = corner - from;
    z0_ = glm::dot(d, z_);
    if (z0_ > 0.0f) z_ = -z_, z0_ = -z0_;  // z points away from the rectangle
    x0_ = glm::dot(d, x_);
    y0_ = glm::dot(d, y_);
    x1_ = x0_ + lx;
    y1_ = y0_ + ly;
    // The normals of the planes through `from` and each edge, in the rectangle's frame, written
    // out: n0 = (0, z0, -y0) / a0, n1 = (-z0, 0, x1) / a1, n2 = (0, -z0, y1) / a2, n3 = (z0, 0, -x0) / a3.
    const float z2 = z0_ * z0_;
    const float a0 = std::sqrt(z2 + y0_ * y0_), a1 = std::sqrt(z2 + x1_ * x1_);
    const float a2 = std::sqrt(z2 + y1_ * y1_), a3 = std::sqrt(z2 + x0_ * x0_);
    // The interior angles g_i = angle(-n_i, n_(i+1)) of the spherical rectangle.
    auto angle = [](float cosine) { return std::acos(std::clamp(cosine, -1.0f, 1.0f)); };
    const float g0 = angle(y0_ * x1_ / (a0 * a1)), g1 = angle(-x1_ * y1_ / (a1 * a2));
    const float g2 = angle(y1_ * x0_ / (a2 * a3)), g3 = angle(-x0_ * y0_ / (a3 * a0));
    constexpr double kTwoPi = 2.0 * 3.14159265358979323846;  // in double: the sum cancels to a small angle
    const double solid_angle = double(g0) + double(g1) + double(g2) + double(g3) - kTwoPi;
    b0_ = -y0_ / a0;
    b1_ = y1_ / a2;
    k_ = static_cast<float>(kTwoPi - double(g2) - double(g3));
    solid_angle_ = static_cast<float>(solid_angle);
    return solid_angle > 1e-3 && std::isfinite(solid_angle) && std::isfinite(b0_) && std::isfinite(b1_);
  }
  float solid_angle() const { return solid_angle_; }
  // The point on the rectangle for u; density 1 / solid_angle() in solid angle at `from`.
  glm::vec3 sample(glm::vec2 u) const {
    const float au = u.x * solid_angle_ + k_;
    const float fu = (std::cos(au) * b0_ - b1_) / std::sin(au);
    float cu = std::copysign(1.0f, fu) / std::sqrt(fu * fu + b0_ * b0_);
    cu = std::clamp(std::isfinite(cu) ? cu : 0.0f, -0.99999994f, 0.99999994f);
    const float xu = std::clamp(-(cu * z0_) / std::sqrt(1.0f - cu * cu), x0_, x1_);
    const float d2 = xu * xu + z0_ * z0_;
    const float h0 = y0_ / std::sqrt(d2 + y0_ * y0_), h1 = y1_ / std::sqrt(d2 + y1_ * y1_);
    const float hv = h0 + u.y * (h1 - h0), hv2 = hv * hv;
    const float yv = hv2 < 1.0f - 1e-6f ? std::clamp(hv * std::sqrt(d2) / std::sqrt(1.0f - hv2), y0_, y1_) : y1_;
    return from_ + xu * x_ + yv * y_ + z0_ * z_;
  }

 private:
  // Set by init() (left uninitialized before: it runs on every light sample near a rectangle).
  glm::vec3 from_, x_, y_, z_;
  float x0_, y0_, x1_, y1_, z0_;
  float b0_, b1_, k_, solid_angle_;
};

inline float power_heuristic(float pdf_a, float pdf_b) {
  float a = pdf_a * pdf_a, b = pdf_b * pdf_b;
  return a > 0.0f ? a / (a + b) : 0.0f;
}

inline float max_component(glm::vec3 v) { return std::max(v.x, std::max(v.y, v.z)); }
inline float luminance(glm::vec3 c) { return 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b; }
inline bool is_finite(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// std::upper_bound's index in sorted[0, n) (how many entries are not above u; n for a NaN u, as
// std::upper_bound gives), without branches on the comparisons: where a random u falls is a coin
// flip per sample, and a branch on it is mispredicted half the time. Up to `count_up_to` entries
// (a light's two triangles) are counted; more are halved with conditional moves (an environment
// map's rows and columns: once the map fits in the cache, std::upper_bound's mispredicted loop is
// most of what its sampling costs).
// The entries may lie `stride` floats apart (a cdf interleaved with its pmf).
inline size_t sorted_upper_bound(const float* sorted, size_t n, float u, size_t count_up_to, size_t stride = 1) {
  if (n <= count_up_to) {
    size_t count = 0;
    for (size_t i = 0; i < n; ++i) count += !(u < sorted[i * stride]);
    return count;
  }
  size_t first = 0;  // the answer lies in [first, first + n]
  while (n > 1) {
    const size_t half = n / 2;
    first = !(u < sorted[(first + half) * stride]) ? first + half : first;
    n -= half;
  }
  return first + !(u < sorted[first * stride]);
}

// A piecewise-constant distribution's arrays as its sampling reads them: cdf (n + 1 entries), pmf
// (n) and, for n >= 64 bins, a guide table of K + 1 entries (Chen's cutpoint method, below; K a power
// of two). Distribution1D holds one; Distribution2D keeps all of its rows' in three flat arrays,
// so that a row's are found from its index alone, without loading the row's object first.
struct BinsView {
  const float* cdf = nullptr;
  const float* pmf = nullptr;
  const uint32_t* guide = nullptr;  // nullptr: no guide table
  size_t n = 0;                     // bins
  size_t guide_intervals = 0;       // K
  size_t stride = 1;                // entry i of cdf and pmf at [i * stride]
};

// With a guide table: guide[k] counts the CDF entries <= k / K, so the answer for u lies in
// [guide[k], guide[k + 1]], a range of about one entry. The same index as the full search, at one
// or two cache lines instead of the search's ten: a large map's rows are sampled at random, and
// each step of a search in a 4 KB row missed the cache (a sky behind a window spent a fifth of its
// time there).
inline size_t upper_bound_index(const BinsView& v, float u) {
  constexpr size_t kLinearScanEntries = 9;
  if (!v.guide) return sorted_upper_bound(v.cdf, v.n + 1, u, kLinearScanEntries, v.stride);
  const size_t last = v.guide_intervals - 1;
  const double scaled = static_cast<double>(u) * static_cast<double>(v.guide_intervals);
  // u outside [0, 1) or NaN: the first or last interval (no cast of a value out of range).
  const size_t k = scaled >= 0.0 && scaled < static_cast<double>(last) ? static_cast<size_t>(scaled)
                   : scaled >= static_cast<double>(last)                ? last
                                                                        : 0;
  const size_t lo = v.guide[k], hi = v.guide[k + 1];
  return lo + sorted_upper_bound(v.cdf + lo * v.stride, hi - lo, u, kLinearScanEntries, v.stride);
}

// The bin u falls in, the position u' in [0,1) within it (reused as a fresh random number) and its pmf.
inline size_t sample_bins(const BinsView& v, float u, float* u_remapped, float* pmf) {
  size_t i = upper_bound_index(v, u);
  i = std::min(i == 0 ? size_t(0) : i - 1, v.n - 1);
  // Skip zero-probability bins that share a CDF value (u exactly on a boundary).
  const size_t k = v.stride;
  while (v.pmf[i * k] == 0.0f && i + 1 < v.n) ++i;
  if (u_remapped) {
    float width = v.cdf[(i + 1) * k] - v.cdf[i * k];
    float t = width > 0.0f ? (u - v.cdf[i * k]) / width : 0.5f;
    *u_remapped = std::min(std::max(t, 0.0f), 0x1.fffffep-1f);
  }
  if (pmf) *pmf = v.pmf[i * k];
  return i;
}

// Piecewise-constant distribution over n bins from non-negative weights (non-finite or negative
// weights count as 0). Sampling is a binary search in the CDF (a linear count for up to 8 bins);
// O(log n), no allocation.
class Distribution1D {
 public:
  Distribution1D() = default;
  explicit Distribution1D(const std::vector<float>& weights) { build(weights.data(), weights.size()); }
  Distribution1D(const float* weights, size_t n) { build(weights, n); }

  size_t size() const { return pmf_.size(); }
  double total() const { return total_; }
  bool valid() const { return total_ > 0.0; }
  float pmf(size_t i) const { return pmf_[i]; }

  // Returns the bin and the position u' in [0,1) within the bin (reused as a fresh random number).
  size_t sample(float u, float* u_remapped = nullptr, float* pmf = nullptr) const {
    return sample_bins(view(), u, u_remapped, pmf);
  }
  BinsView view() const {
    return BinsView{cdf_.data(), pmf_.data(), guide_.empty() ? nullptr : guide_.data(), pmf_.size(),
                    guide_.empty() ? 0 : guide_.size() - 1};
  }

 private:
  static constexpr size_t kGuidedFrom = 64;  // bins; fewer stay in a cache line or two anyway

  // guide_[k] = #{i : cdf_[i] <= k / K} for k = 0 .. K, K the least power of two >= the bins.
  void build_guide() {
    const size_t n = cdf_.size();
    if (n - 1 < kGuidedFrom) return;
    size_t intervals = 1;
    while (intervals < n - 1) intervals *= 2;
    guide_.resize(intervals + 1);
    size_t count = 0;
    for (size_t k = 0; k <= intervals; ++k) {
      const double edge = static_cast<double>(k) / static_cast<double>(intervals);
      while (count < n && static_cast<double>(cdf_[count]) <= edge) ++count;
      guide_[k] = static_cast<uint32_t>(count);
    }
  }

  void build(const float* weights, size_t n) {
    pmf_.assign(n, 0.0f);
    cdf_.assign(n + 1, 0.0f);
    std::vector<double> cdf(n + 1, 0.0);
    for (size_t i = 0; i < n; ++i) {
      double w = std::isfinite(weights[i]) && weights[i] > 0.0f ? weights[i] : 0.0;
      cdf[i + 1] = cdf[i] + w;
    }
    total_ = cdf[n];
    if (!(total_ > 0.0)) return;
    for (size_t i = 0; i < n; ++i) {
      pmf_[i] = static_cast<float>((cdf[i + 1] - cdf[i]) / total_);
      cdf_[i + 1] = static_cast<float>(cdf[i + 1] / total_);
    }
    cdf_[n] = 1.0f;
    build_guide();
  }

  std::vector<float> pmf_;
  std::vector<float> cdf_;
  std::vector<uint32_t> guide_;  // empty below kGuidedFrom bins
  double total_ = 0.0;
};

// Piecewise-constant 2D distribution on [0,1)^2 over a width x height grid (row = y): a marginal
// over rows and one conditional per row. pdf is a density with respect to area in [0,1)^2.
class Distribution2D {
 public:
  Distribution2D() = default;
  Distribution2D(const std::vector<float>& weights, int width, int height) : width_(width), height_(height) {
    std::vector<float> row_sums(height);
    std::vector<Distribution1D> rows;
    rows.reserve(height);
    for (int y = 0; y < height; ++y) {
      rows.emplace_back(weights.data() + static_cast<size_t>(y) * width, width);
      row_sums[y] = static_cast<float>(rows.back().total());
    }
    marginal_ = Distribution1D(row_sums);
    flatten_rows(rows);
    // The densities pdf() reads, as sample() computes them: one load instead of two dependent ones
    // (the row's pmf, then the marginal's), which missed the cache at every MIS weight.
    density_.resize(static_cast<size_t>(width) * height);
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x)
        density_[static_cast<size_t>(y) * width + x] =
            marginal_.pmf(y) * rows[y].pmf(x) * static_cast<float>(width_) * static_cast<float>(height_);
  }
  bool valid() const { return marginal_.valid(); }

  glm::vec2 sample(glm::vec2 u, float* pdf) const {
    float uy, ux, pmf_y, pmf_x;
    size_t y = marginal_.sample(u.y, &uy, &pmf_y);
    size_t x = sample_bins(row(y), u.x, &ux, &pmf_x);
    *pdf = pmf_y * pmf_x * static_cast<float>(width_) * static_cast<float>(height_);
    return glm::vec2((static_cast<float>(x) + ux) / width_, (static_cast<float>(y) + uy) / height_);
  }

  float pdf(glm::vec2 uv) const {
    int x = std::min(std::max(static_cast<int>(uv.x * width_), 0), width_ - 1);
    int y = std::min(std::max(static_cast<int>(uv.y * height_), 0), height_ - 1);
    return density_[static_cast<size_t>(y) * width_ + x];
  }

 private:
  // Every row has as many bins, and so as long a guide table: row y's start at y times a row's
  // length. A row's cdf and pmf are interleaved (cdf[i], pmf[i]), so that the entries a sample
  // reads after its guide table share a cache line: on a sky behind a window each of the three
  // arrays missed the cache at nearly every sample.
  void flatten_rows(const std::vector<Distribution1D>& rows) {
    const size_t w = static_cast<size_t>(width_);
    // Rows without light have no guide table: theirs stays 0s (never sampled; it leads to the row's
    // last bin, as the full search does).
    guide_intervals_ = 0;
    for (const Distribution1D& r : rows) guide_intervals_ = std::max(guide_intervals_, r.view().guide_intervals);
    bins_.assign(rows.size() * 2 * (w + 1), 0.0f);
    guide_.resize(guide_intervals_ > 0 ? rows.size() * (guide_intervals_ + 1) : 0);
    for (size_t y = 0; y < rows.size(); ++y) {
      const BinsView v = rows[y].view();
      float* row = bins_.data() + y * 2 * (w + 1);
      for (size_t i = 0; i <= w; ++i) row[2 * i] = v.cdf[i];
      for (size_t i = 0; i < w; ++i) row[2 * i + 1] = v.pmf[i];
      if (v.guide) std::copy(v.guide, v.guide + guide_intervals_ + 1, guide_.begin() + y * (guide_intervals_ + 1));
    }
  }
  BinsView row(size_t y) const {
    const size_t w = static_cast<size_t>(width_);
    const float* bins = bins_.data() + y * 2 * (w + 1);
    return BinsView{bins, bins + 1, guide_intervals_ > 0 ? guide_.data() + y * (guide_intervals_ + 1) : nullptr, w,
                    guide_intervals_, 2};
  }

  int width_ = 0, height_ = 0;
  std::vector<float> density_;
  std::vector<float> bins_;       // per row (cdf[i], pmf[i]) for i <= width (pmf[width] = 0)
  std::vector<uint32_t> guide_;   // the rows' guide tables (guide_intervals_ + 1 each), if any
  size_t guide_intervals_ = 0;
  Distribution1D marginal_;
};

}  // namespace pxf
