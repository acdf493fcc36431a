#include "bench/plot.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "image/image.h"

namespace pxf {

namespace {
const char* kColors[] = {"#d62728", "#1f77b4", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b"};

struct Axis {
  double lo = INFINITY, hi = -INFINITY;
  bool log = false;
  double map(double v, double a, double b) const {
    const double t = log ? (std::log10(v) - std::log10(lo)) / (std::log10(hi) - std::log10(lo)) : (v - lo) / (hi - lo);
    return a + t * (b - a);
  }
  void include(double v) {
    if (!std::isfinite(v) || (log && v <= 0)) return;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  void finish() {
    if (!(lo < hi)) hi = lo + (lo == 0 ? 1 : std::abs(lo) * 0.1), lo = lo - (lo == 0 ? 0 : std::abs(lo) * 0.1);
    if (log) lo = std::pow(10, std::floor(std::log10(lo))), hi = std::pow(10, std::ceil(std::log10(hi)));
  }
  std::vector<double> ticks() const {
    std::vector<double> t;
    if (log) {
      for (double v = lo; v <= hi * 1.0001; v *= 10) t.push_back(v);
    } else {
      for (int i = 0; i <= 5; ++i) t.push_back(lo + (hi - lo) * i / 5);
    }
    return t;
  }
};
}  // namespace

void write_svg_plot(const std::string& path, const PlotSpec& spec, const std::vector<PlotSeries>& series) {
  const double W = 720, H = 460, left = 80, right = 180, top = 40, bottom = 60;
  Axis ax, ay;
  ax.log = spec.log_x;
  ay.log = spec.log_y;
  for (const auto& s : series)
    for (size_t i = 0; i < s.x.size(); ++i) ax.include(s.x[i]), ay.include(s.y[i]);
  ax.finish();
  ay.finish();
  std::ostringstream svg;
  svg << "<svg xmlns='http://www.w3.org/2000/svg' width='" << W << "' height='" << H
      << "' font-family='sans-serif' font-size='12'>\n<rect width='100%' height='100%' fill='white'/>\n";
  svg << "<text x='" << W / 2 << "' y='22' text-anchor='middle' font-size='15'>" << spec.title << "</text>\n";
  const double x0 = left, x1 = W - right, y0 = H - bottom, y1 = top;
  svg << "<rect x='" << x0 << "' y='" << y1 << "' width='" << x1 - x0 << "' height='" << y0 - y1
      << "' fill='none' stroke='black'/>\n";
  for (double t : ax.ticks()) {
    const double x = ax.map(t, x0, x1);
    svg << "<line x1='" << x << "' y1='" << y0 << "' x2='" << x << "' y2='" << y1 << "' stroke='#ddd'/>"
        << "<text x='" << x << "' y='" << y0 + 16 << "' text-anchor='middle'>" << t << "</text>\n";
  }
  for (double t : ay.ticks()) {
    const double y = ay.map(t, y0, y1);
    svg << "<line x1='" << x0 << "' y1='" << y << "' x2='" << x1 << "' y2='" << y << "' stroke='#ddd'/>"
        << "<text x='" << x0 - 6 << "' y='" << y + 4 << "' text-anchor='end'>" << t << "</text>\n";
  }
  svg << "<text x='" << (x0 + x1) / 2 << "' y='" << H - 18 << "' text-anchor='middle'>" << spec.x_label << "</text>\n";
  svg << "<text transform='translate(20," << (y0 + y1) / 2 << ") rotate(-90)' text-anchor='middle'>" << spec.y_label
      << "</text>\n";
  for (size_t k = 0; k < series.size(); ++k) {
    const auto& s = series[k];
    const char* color = kColors[k % 6];
    std::ostringstream points;
    for (size_t i = 0; i < s.x.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i]) || (ax.log && s.x[i] <= 0) || (ay.log && s.y[i] <= 0))
        continue;
      const double x = ax.map(s.x[i], x0, x1), y = ay.map(s.y[i], y0, y1);
      if (s.markers)
        svg << "<circle cx='" << x << "' cy='" << y << "' r='4' fill='" << color << "'/>\n";
      else
        points << x << "," << y << " ";
    }
    if (!s.markers)
      svg << "<polyline fill='none' stroke='" << color << "' stroke-width='2' points='" << points.str() << "'/>\n";
    const double ly = top + 10 + 20 * k;
    svg << "<rect x='" << x1 + 12 << "' y='" << ly - 8 << "' width='14' height='10' fill='" << color << "'/>"
        << "<text x='" << x1 + 32 << "' y='" << ly << "'>" << s.name << "</text>\n";
  }
  svg << "</svg>\n";
  const std::string text = svg.str();
  write_file_atomically(path, [&](const std::string& tmp) {
    std::ofstream out(tmp);
    out << text;
    if (!out) throw Error(path + ": cannot write");
  });
}

}  // namespace pxf
