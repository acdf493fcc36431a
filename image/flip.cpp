// LDR-FLIP from the paper (see flip.h). Both pipelines run on separable kernels: every 2D kernel
// the paper uses is a sum of products g(x) g(y), so filtering rows then columns gives the same
// result as the 2D kernel at a fraction of the cost. Borders repeat the edge pixel.
#include "image/flip.h"

#include <algorithm>
#include <cmath>

namespace pxf {

namespace {
constexpr double kPi = 3.14159265358979323846;

// Linear sRGB <-> CIE XYZ (D65).
constexpr double kRgbToXyz[3][3] = {
    {0.4124564, 0.3575761, 0.1804375}, {0.2126729, 0.7151522, 0.0721750}, {0.0193339, 0.1191920, 0.9503041}};
constexpr double kXyzToRgb[3][3] = {
    {3.2404542, -1.5371385, -0.4985314}, {-0.9692660, 1.8760108, 0.0415560}, {0.0556434, -0.2040259, 1.0572252}};

struct Vec3 {
  double v[3];
};
Vec3 mul(const double m[3][3], const Vec3& x) {
  Vec3 r{};
  for (int i = 0; i < 3; ++i) r.v[i] = m[i][0] * x.v[0] + m[i][1] * x.v[1] + m[i][2] * x.v[2];
  return r;
}
// The white point: XYZ of linear RGB (1,1,1).
Vec3 white_xyz() { return mul(kRgbToXyz, {{1.0, 1.0, 1.0}}); }

// One channel of an image, row-major.
struct Plane {
  int width = 0, height = 0;
  std::vector<double> v;
  Plane(int w, int h) : width(w), height(h), v(static_cast<size_t>(w) * h, 0.0) {}
  double& at(int x, int y) { return v[static_cast<size_t>(y) * width + x]; }
  double at(int x, int y) const { return v[static_cast<size_t>(y) * width + x]; }
};

using Kernel1D = std::vector<double>;  // 2r+1 taps, the centre at index r

// out(x, y) = sum_i sum_j kx[i] ky[j] in(x + i - r, y + j - r), borders clamped.
Plane correlate_separable(const Plane& in, const Kernel1D& kx, const Kernel1D& ky) {
  const int rx = static_cast<int>(kx.size() / 2), ry = static_cast<int>(ky.size() / 2);
  Plane rows(in.width, in.height), out(in.width, in.height);
  for (int y = 0; y < in.height; ++y)
    for (int x = 0; x < in.width; ++x) {
      double s = 0;
      for (int i = -rx; i <= rx; ++i) s += kx[i + rx] * in.at(std::clamp(x + i, 0, in.width - 1), y);
      rows.at(x, y) = s;
    }
  for (int y = 0; y < in.height; ++y)
    for (int x = 0; x < in.width; ++x) {
      double s = 0;
      for (int j = -ry; j <= ry; ++j) s += ky[j + ry] * rows.at(x, std::clamp(y + j, 0, in.height - 1));
      out.at(x, y) = s;
    }
  return out;
}

// --- Color pipeline -------------------------------------------------------------------------

// The contrast sensitivity of one opponent channel as a sum of two Gaussians in the spatial domain,
// a sqrt(pi/b) exp(-pi^2 x^2 / b) with x in degrees (the paper's parameters).
struct CsfChannel {
  double a1, b1, a2, b2;
};
constexpr CsfChannel kCsfAchromatic{1.0, 0.0047, 0.0, 1e-5};
constexpr CsfChannel kCsfRedGreen{1.0, 0.0053, 0.0, 1e-5};
constexpr CsfChannel kCsfBlueYellow{34.1, 0.04, 13.5, 0.025};
constexpr double kCsfLargestB = 0.04;

int csf_radius(double ppd) { return static_cast<int>(std::ceil(3.0 * std::sqrt(kCsfLargestB / (2 * kPi * kPi)) * ppd)); }

// Filters a plane with the channel's CSF, normalised to unit sum over the 2D footprint: each
// Gaussian term is separable, so the result is the weighted sum of the normalised terms, each
// weighted by its share of the 2D kernel's sum.
Plane csf_filter(const Plane& in, const CsfChannel& c, double ppd) {
  const int r = csf_radius(ppd);
  struct Term {
    Kernel1D k;
    double weight2d;
  };
  std::vector<Term> terms;
  for (auto [a, b] : {std::pair{c.a1, c.b1}, std::pair{c.a2, c.b2}}) {
    if (a == 0) continue;
    Kernel1D k(2 * r + 1);
    double sum = 0;
    for (int i = -r; i <= r; ++i) {
      const double deg = i / ppd;
      sum += k[i + r] = std::exp(-kPi * kPi * deg * deg / b);
    }
    for (double& w : k) w /= sum;
    terms.push_back({k, a * std::sqrt(kPi / b) * sum * sum});
  }
  double total = 0;
  for (const Term& t : terms) total += t.weight2d;
  Plane out(in.width, in.height);
  for (const Term& t : terms) {
    const Plane f = correlate_separable(in, t.k, t.k);
    for (size_t p = 0; p < out.v.size(); ++p) out.v[p] += t.weight2d / total * f.v[p];
  }
  return out;
}

double lab_f(double t) {
  constexpr double d = 6.0 / 29.0;
  return t > d * d * d ? std::cbrt(t) : t / (3 * d * d) + 4.0 / 29.0;
}

// YyCxCz: the linearised CIELAB opponent space in which the paper filters.
struct Opponent {
  Plane yy, cx, cz;
};
Opponent opponent_from_display(const Image& display) {
  const Vec3 w = white_xyz();
  Opponent o{Plane(display.width, display.height), Plane(display.width, display.height),
             Plane(display.width, display.height)};
  for (int y = 0; y < display.height; ++y)
    for (int x = 0; x < display.width; ++x) {
      Vec3 rgb{};
      for (int i = 0; i < 3; ++i) {
        const float v = display.at(x, y, i);
        rgb.v[i] = std::isnan(v) ? 0.0 : linear_from_srgb(std::clamp(v, 0.0f, 1.0f));
      }
      const Vec3 xyz = mul(kRgbToXyz, rgb);
      const double fx = xyz.v[0] / w.v[0], fy = xyz.v[1] / w.v[1], fz = xyz.v[2] / w.v[2];
      o.yy.at(x, y) = 116 * fy - 16;
      o.cx.at(x, y) = 500 * (fx - fy);
      o.cz.at(x, y) = 200 * (fy - fz);
    }
  return o;
}

// Hunt-adjusted CIELAB of the CSF-filtered image, clamped to the RGB cube first.
std::vector<Lab> filtered_lab(const Opponent& o, double ppd) {
  const Plane yy = csf_filter(o.yy, kCsfAchromatic, ppd);
  const Plane cx = csf_filter(o.cx, kCsfRedGreen, ppd);
  const Plane cz = csf_filter(o.cz, kCsfBlueYellow, ppd);
  const Vec3 w = white_xyz();
  std::vector<Lab> lab(yy.v.size());
  for (size_t p = 0; p < lab.size(); ++p) {
    const double fy = (yy.v[p] + 16) / 116, fx = cx.v[p] / 500 + fy, fz = fy - cz.v[p] / 200;
    Vec3 rgb = mul(kXyzToRgb, {{fx * w.v[0], fy * w.v[1], fz * w.v[2]}});
    for (double& c : rgb.v) c = std::clamp(c, 0.0, 1.0);
    lab[p] = flip_hunt_adjust(flip_lab_from_linear_rgb(rgb.v[0], rgb.v[1], rgb.v[2]));
  }
  return lab;
}

// --- Feature pipeline -----------------------------------------------------------------------

constexpr double kFeatureWidthDegrees = 0.082;  // distance between the edge detector's peaks
constexpr double kFeatureExponent = 0.5;        // q_f

// Scales the positive taps to sum 1 and the negative ones to sum -1, as the paper does so that
// a detector's response stays in [-1, 1] on inputs in [0, 1].
void balance_signs(Kernel1D& k) {
  double pos = 0, neg = 0;
  for (double w : k) (w > 0 ? pos : neg) += w;
  for (double& w : k) w = w > 0 ? w / pos : (w < 0 ? w / -neg : 0.0);
}

struct FeatureKernels {
  Kernel1D gauss, first, second;  // the Gaussian (unit sum) and its 1st and 2nd derivatives
};
FeatureKernels feature_kernels(double ppd) {
  const double sigma = 0.5 * kFeatureWidthDegrees * ppd;
  const int r = static_cast<int>(std::ceil(3 * sigma));
  FeatureKernels k{Kernel1D(2 * r + 1), Kernel1D(2 * r + 1), Kernel1D(2 * r + 1)};
  double sum = 0;
  for (int i = -r; i <= r; ++i) {
    const double g = std::exp(-double(i) * i / (2 * sigma * sigma));
    sum += k.gauss[i + r] = g;
    k.first[i + r] = -i * g;
    k.second[i + r] = (double(i) * i / (sigma * sigma) - 1) * g;
  }
  for (double& w : k.gauss) w /= sum;
  balance_signs(k.first);
  balance_signs(k.second);
  return k;
}

struct Features {
  Plane edge, point;  // gradient magnitudes of the edge and point detectors
};
Features detect_features(const Plane& yy, double ppd) {
  Plane y(yy.width, yy.height);  // normalised luminance Y / Y_white in [0, 1]
  for (size_t p = 0; p < y.v.size(); ++p) y.v[p] = (yy.v[p] + 16) / 116;
  const FeatureKernels k = feature_kernels(ppd);
  auto magnitude = [&](const Kernel1D& d) {
    Plane gx = correlate_separable(y, d, k.gauss), gy = correlate_separable(y, k.gauss, d);
    for (size_t p = 0; p < gx.v.size(); ++p) gx.v[p] = std::hypot(gx.v[p], gy.v[p]);
    return gx;
  };
  return {magnitude(k.first), magnitude(k.second)};
}
}  // namespace

Lab flip_lab_from_linear_rgb(double r, double g, double b) {
  const Vec3 xyz = mul(kRgbToXyz, {{r, g, b}}), w = white_xyz();
  const double fx = lab_f(xyz.v[0] / w.v[0]), fy = lab_f(xyz.v[1] / w.v[1]), fz = lab_f(xyz.v[2] / w.v[2]);
  return {116 * fy - 16, 500 * (fx - fy), 200 * (fy - fz)};
}

Lab flip_hunt_adjust(const Lab& lab) { return {lab.L, 0.01 * lab.L * lab.a, 0.01 * lab.L * lab.b}; }

double flip_hyab(const Lab& x, const Lab& y) {
  return std::abs(x.L - y.L) + std::hypot(x.a - y.a, x.b - y.b);
}

double flip_max_color_distance() {
  static const double cmax = flip_hyab(flip_hunt_adjust(flip_lab_from_linear_rgb(0, 1, 0)),
                                       flip_hunt_adjust(flip_lab_from_linear_rgb(0, 0, 1)));
  return cmax;
}

double flip_color_remap(double hyab_distance) {
  constexpr double qc = 0.7, pc = 0.4, pt = 0.95;
  const double cmax = std::pow(flip_max_color_distance(), qc);
  const double d = std::pow(std::max(hyab_distance, 0.0), qc);
  if (d < pc * cmax) return pt / (pc * cmax) * d;
  return std::min(1.0, pt + (d - pc * cmax) / (cmax - pc * cmax) * (1 - pt));
}

Image flip_error_map(const Image& test_display, const Image& reference_display, double ppd) {
  if (test_display.width != reference_display.width || test_display.height != reference_display.height)
    throw Error("FLIP: image sizes differ");
  if (test_display.num_channels() < 3 || reference_display.num_channels() < 3)
    throw Error("FLIP: both images need R,G,B");
  if (!(ppd > 0) || !std::isfinite(ppd)) throw Error("FLIP: pixels per degree must be positive");
  const Opponent ot = opponent_from_display(test_display), orf = opponent_from_display(reference_display);
  const std::vector<Lab> lt = filtered_lab(ot, ppd), lr = filtered_lab(orf, ppd);
  const Features ft = detect_features(ot.yy, ppd), fr = detect_features(orf.yy, ppd);
  Image out = Image::gray(test_display.width, test_display.height);
  for (size_t p = 0; p < lt.size(); ++p) {
    const double color = flip_color_remap(flip_hyab(lt[p], lr[p]));
    const double feature_diff = std::max(std::abs(ft.edge.v[p] - fr.edge.v[p]), std::abs(ft.point.v[p] - fr.point.v[p]));
    const double feature = std::pow(std::min(1.0, feature_diff / std::sqrt(2.0)), kFeatureExponent);
    out.pixels[p] = static_cast<float>(std::pow(color, 1.0 - feature));
  }
  return out;
}

}  // namespace pxf
