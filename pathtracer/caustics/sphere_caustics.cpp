#include "pathtracer/caustics/sphere_caustics.h"

#include <algorithm>
#include <cmath>

namespace pxf {

namespace {

constexpr double kHalfPi = 1.57079632679489661923;

// The path from xr (relative to the centre) along unit w: in 2D (the solver's plane) or 3D alike.
template <class V>
bool trace_relative(const V& xr, const V& w, double radius, bool mirror, double ior, V* origin, V* direction) {
  const double along = glm::dot(xr, w);
  const double outside = glm::dot(xr, xr) - radius * radius;
  if (!(outside > 0.0) || !(along < 0.0)) return false;  // inside, or heading away
  const double disc = along * along - outside;
  if (!(disc > 0.0)) return false;  // misses
  const V entry = xr + (-along - std::sqrt(disc)) * w;
  const V n1 = entry / radius;
  if (mirror) {
    *origin = entry;
    *direction = w - 2.0 * glm::dot(w, n1) * n1;
    return true;
  }
  const double cos_in = -glm::dot(w, n1), eta = 1.0 / ior;
  const double k_in = 1.0 - eta * eta * (1.0 - cos_in * cos_in);
  if (!(k_in >= 0.0)) return false;
  const V inside = glm::normalize(eta * w + (eta * cos_in - std::sqrt(k_in)) * n1);
  const V exit = entry - 2.0 * glm::dot(entry, inside) * inside;  // the chord's other end
  const V n2 = exit / radius;
  const double cos_out = glm::dot(inside, n2);
  const double k_out = 1.0 - ior * ior * (1.0 - cos_out * cos_out);
  if (!(k_out >= 0.0)) return false;  // totally reflected: left to the path
  *origin = exit;
  *direction = glm::normalize(ior * inside - (ior * cos_out - std::sqrt(k_out)) * n2);
  return true;
}

// The root of g in [lo, hi], where it changes sign, by the Illinois variant of regula falsi (a
// handful of evaluations where bisection takes fifty); false when g is undefined inside.
template <class F>
bool refine_root(const F& g, double lo, double g_lo, double hi, double g_hi, double tolerance, double* root) {
  int side = 0;
  for (int k = 0; k < 100; ++k) {
    const double x = (lo * g_hi - hi * g_lo) / (g_hi - g_lo);
    if (!(x > lo && x < hi)) {  // converged to an end in rounding
      *root = std::min(std::max(x, lo), hi);
      return true;
    }
    double g_x;
    if (!g(x, &g_x)) return false;
    if (g_x == 0.0 || hi - lo < tolerance) {
      *root = x;
      return true;
    }
    if ((g_x < 0.0) == (g_lo < 0.0)) {
      lo = x;
      g_lo = g_x;
      if (side == -1) g_hi *= 0.5;
      side = -1;
    } else {
      hi = x;
      g_hi = g_x;
      if (side == 1) g_lo *= 0.5;
      side = 1;
    }
    if (std::abs(hi - lo) < tolerance) {
      *root = 0.5 * (lo + hi);
      return true;
    }
  }
  *root = 0.5 * (lo + hi);
  return true;
}

// The scan's points as fractions of the radius, even in the entry angle (b = r sin a): the paths
// bend fastest near the rim. Computed once per size (the sines cost as much as the scan's traces).
const std::vector<double>& scan_steps(int count) {
  const auto make = [](int n) {
    std::vector<double> steps(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) steps[i] = std::sin(kHalfPi * (-1.0 + (2.0 * i + 1.0) / n));
    return steps;
  };
  static const std::vector<double> glass = make(kGlassScan), mirror = make(kMirrorScan);
  return count == kMirrorScan ? mirror : glass;
}

// Where the ray o + t d (t > 0) crosses the emitter's triangle.
bool hit_emitter(const SphereCausticSampler::Emitter& e, const glm::dvec3& o, const glm::dvec3& d, glm::dvec3* y) {
  const glm::dvec3 p = glm::cross(d, e.e2);
  const double det = glm::dot(e.e1, p);
  if (!(std::abs(det) > 1e-300)) return false;
  const double inv = 1.0 / det;
  const glm::dvec3 s = o - e.p0;
  const double u = glm::dot(s, p) * inv;
  if (u < 0.0 || u > 1.0) return false;
  const glm::dvec3 q = glm::cross(s, e.e1);
  const double v = glm::dot(d, q) * inv;
  if (v < 0.0 || u + v > 1.0) return false;
  const double t = glm::dot(e.e2, q) * inv;
  if (!(t > 0.0)) return false;
  *y = o + t * d;
  return true;
}

// Where the path along w leaves the sphere and meets the plane through p0 with normal n.
bool plane_point(const SphereCaster& c, const glm::dvec3& x, const glm::dvec3& w, const glm::dvec3& p0,
                 const glm::dvec3& n, glm::dvec3* y) {
  glm::dvec3 o, d;
  if (!trace_sphere_caster(c, x, w, &o, &d)) return false;
  const double denominator = glm::dot(d, n);
  if (!(std::abs(denominator) > 1e-300)) return false;
  *y = o + (glm::dot(p0 - o, n) / denominator) * d;
  return true;
}

// |dA_y / d omega| of the map from a direction at x to the point its path meets the emitter's
// plane, by central differences (double: the differences keep about 11 digits).
double area_per_solid_angle(const SphereCaster& c, const glm::dvec3& x, const glm::dvec3& w,
                            const SphereCausticSampler::Emitter& e) {
  constexpr double h = 1e-5;
  const glm::dvec3 n = glm::normalize(glm::cross(e.e1, e.e2));
  const glm::dvec3 helper = std::abs(w.x) < 0.6 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
  const glm::dvec3 t1 = glm::normalize(glm::cross(w, helper)), t2 = glm::cross(w, t1);
  glm::dvec3 a, b, c2, d;
  if (!plane_point(c, x, glm::normalize(w + h * t1), e.p0, n, &a) ||
      !plane_point(c, x, glm::normalize(w - h * t1), e.p0, n, &b) ||
      !plane_point(c, x, glm::normalize(w + h * t2), e.p0, n, &c2) ||
      !plane_point(c, x, glm::normalize(w - h * t2), e.p0, n, &d))
    return 0.0;
  return glm::length(glm::cross(a - b, c2 - d)) / (4.0 * h * h);
}

}  // namespace

bool fit_sphere_caster(const std::vector<glm::vec3>& positions, const std::vector<glm::vec3>& normals,
                       SphereCaster* out) {
  if (positions.size() < 4 || normals.size() != positions.size()) return false;
  glm::dvec3 lo(INFINITY), hi(-INFINITY);
  for (const glm::vec3& p : positions) {
    lo = glm::min(lo, glm::dvec3(p));
    hi = glm::max(hi, glm::dvec3(p));
  }
  const glm::dvec3 center = 0.5 * (lo + hi);
  double mean = 0.0;
  for (const glm::vec3& p : positions) mean += glm::length(glm::dvec3(p) - center);
  mean /= double(positions.size());
  if (!(mean > 0.0) || !std::isfinite(mean)) return false;
  for (size_t i = 0; i < positions.size(); ++i) {
    const glm::dvec3 radial = glm::dvec3(positions[i]) - center;
    const double distance = glm::length(radial);
    if (std::abs(distance - mean) > kSphereFitTolerance * mean) return false;
    // Shaded as a sphere: the vertex normals radial (a cube's corners lie on a sphere too).
    const double alignment = std::abs(glm::dot(glm::dvec3(normals[i]), radial)) / (glm::length(glm::dvec3(normals[i])) * distance);
    if (!(alignment > 1.0 - kSphereFitTolerance)) return false;
  }
  out->center = center;
  out->radius = mean;
  return true;
}

bool trace_sphere_caster(const SphereCaster& c, const glm::dvec3& x, const glm::dvec3& w, glm::dvec3* origin,
                         glm::dvec3* direction) {
  glm::dvec3 o;
  if (!trace_relative(x - c.center, w, c.radius, c.mirror, c.ior, &o, direction)) return false;
  *origin = o + c.center;
  return true;
}

int solve_sphere_caster(const SphereCaster& c, const glm::dvec3& x, const glm::dvec3& y, glm::dvec3* directions) {
  const glm::dvec3 xr = x - c.center, yr = y - c.center;
  const double dx = glm::length(xr), r = c.radius;
  if (!(dx > r) || !(glm::length(yr) > r)) return 0;
  const glm::dvec3 e1 = xr / dx;
  const glm::dvec3 across = yr - glm::dot(yr, e1) * e1;
  const double height = glm::length(across);
  if (!(height > 1e-9 * glm::length(yr))) return 0;
  const glm::dvec3 e2 = across / height;
  const glm::dvec2 x2(dx, 0.0), y2(glm::dot(yr, e1), height);
  // The ray from x2 at signed distance b from the centre, and how far y2 lies off its exit ray's
  // line (continuous in b wherever the path exists; whether y2 is ahead is checked at the root).
  const auto direction_of = [&](double b) {
    const double s = b / dx;
    return glm::dvec2(-std::sqrt(1.0 - s * s), s);
  };
  const auto miss = [&](double b, double* g) {
    glm::dvec2 o, d;
    if (!trace_relative(x2, direction_of(b), r, c.mirror, c.ior, &o, &d)) return false;
    const glm::dvec2 to = y2 - o;
    *g = d.x * to.y - d.y * to.x;
    return true;
  };
  const auto ahead = [&](double b) {
    glm::dvec2 o, d;
    return trace_relative(x2, direction_of(b), r, c.mirror, c.ior, &o, &d) && glm::dot(y2 - o, d) > 0.0;
  };
  int count = 0;
  const std::vector<double>& steps = scan_steps(c.mirror ? kMirrorScan : kGlassScan);
  const int scan = static_cast<int>(steps.size());
  const auto scan_point = [&](int i) { return r * steps[i]; };
  double b_prev = scan_point(0), g_prev = 0.0;
  bool valid_prev = miss(b_prev, &g_prev);
  for (int i = 1; i < scan && count < kMaxSphereCasterPaths; ++i) {
    const double b_next = scan_point(i);
    double g_next = 0.0;
    const bool valid_next = miss(b_next, &g_next);
    if (valid_prev && valid_next && (g_prev < 0.0) != (g_next < 0.0)) {
      double root;
      if (refine_root(miss, b_prev, g_prev, b_next, g_next, 1e-13 * r, &root) && std::abs(root) < kSphereCasterRim * r &&
          ahead(root)) {
        const glm::dvec2 d = direction_of(root);
        directions[count++] = glm::normalize(d.x * e1 + d.y * e2);
      }
    }
    b_prev = b_next;
    g_prev = g_next;
    valid_prev = valid_next;
  }
  return count;
}

SphereCausticSampler::SphereCausticSampler(std::vector<Emitter> emitters, const std::vector<float>& powers)
    : emitters_(std::move(emitters)), choice_(powers) {
  if (!choice_.valid()) emitters_.clear();
}

bool SphereCausticSampler::sample(const SphereCaster& caster, glm::vec3 x, float u_select, glm::vec2 u_point,
                                  glm::vec3* w, float* pdf) const {
  if (emitters_.empty()) return false;
  float u_path;
  const size_t emitter = choice_.sample(u_select, &u_path);
  const Emitter& e = emitters_[emitter];
  const glm::dvec2 b(sample_triangle_barycentrics(u_point));
  const glm::dvec3 y = e.p0 + b.x * e.e1 + b.y * e.e2;
  glm::dvec3 paths[kMaxSphereCasterPaths];
  const int count = solve_sphere_caster(caster, glm::dvec3(x), y, paths);
  if (count == 0) return false;
  *w = glm::vec3(paths[std::min(count - 1, static_cast<int>(u_path * float(count)))]);
  *pdf = density(caster, glm::dvec3(x), glm::normalize(glm::dvec3(*w)), static_cast<int>(emitter), count);
  return true;
}

float SphereCausticSampler::pdf(const SphereCaster& caster, glm::vec3 x, glm::vec3 w) const {
  return density(caster, glm::dvec3(x), glm::normalize(glm::dvec3(w)), -1, 0);
}

float SphereCausticSampler::density(const SphereCaster& caster, const glm::dvec3& x, const glm::dvec3& w, int known,
                                    int known_count) const {
  glm::dvec3 o, d;
  if (emitters_.empty() || !trace_sphere_caster(caster, x, w, &o, &d)) return 0.0f;
  // Solutions closer than this to w are w: the solver's are exact to ~1e-13, a float direction to ~1e-7.
  constexpr double kSame = 1e-5;
  double density = 0.0;
  for (size_t i = 0; i < emitters_.size(); ++i) {
    const Emitter& e = emitters_[i];
    glm::dvec3 y;
    if (choice_.pmf(i) == 0.0f || !(e.area > 0.0) || !hit_emitter(e, o, d, &y)) continue;  // never drawn
    int count = known_count;
    if (static_cast<int>(i) != known) {  // is w among the paths to this emitter's point too?
      glm::dvec3 paths[kMaxSphereCasterPaths];
      count = solve_sphere_caster(caster, x, y, paths);
      bool found = false;
      for (int k = 0; k < count && !found; ++k) found = glm::length(paths[k] - w) < kSame;
      if (!found) continue;
    }
    density += double(choice_.pmf(i)) / e.area * area_per_solid_angle(caster, x, w, e) / count;
  }
  return static_cast<float>(density);
}

}  // namespace pxf
