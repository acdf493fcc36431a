// Minimal SVG line plots for `pxf bench` (no plotting dependency): log or linear axes, a legend.
#pragma once
#include <string>
#include <vector>

namespace pxf {

struct PlotSeries {
  std::string name;
  std::vector<double> x, y;
  bool markers = false;  // draw points instead of a line
};

struct PlotSpec {
  std::string title, x_label, y_label;
  bool log_x = false, log_y = false;
};

void write_svg_plot(const std::string& path, const PlotSpec& spec, const std::vector<PlotSeries>& series);

}  // namespace pxf
