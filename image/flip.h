// LDR-FLIP (Andersson, Nilsson, Akenine-Moeller, Oskarsson, Astroem, Fairchild 2020, "FLIP: A
// Difference Evaluator for Alternating Images"), written from the paper: a per-pixel error in
// [0,1] between two sRGB-encoded display images seen at a given number of pixels per degree.
#pragma once
#include "image/image.h"

namespace pxf {

constexpr double kFlipDefaultPpd = 67.0;  // the paper's: 0.7 m from a 24" 4K monitor

// Per-pixel FLIP, "Y" in [0,1], of two "R,G,B" images holding sRGB-encoded values in [0,1]
// (values outside are clamped). Symmetric in its arguments. Throws pxf::Error on a size mismatch.
Image flip_error_map(const Image& test_display, const Image& reference_display, double pixels_per_degree = kFlipDefaultPpd);

// Pieces of the color pipeline, exposed for tests.
struct Lab {
  double L, a, b;
};
Lab flip_lab_from_linear_rgb(double r, double g, double b);  // CIELAB, D65 white of linear sRGB (1,1,1)
Lab flip_hunt_adjust(const Lab& lab);                           // a, b scaled by 0.01 L
double flip_hyab(const Lab& x, const Lab& y);                   // |dL| + sqrt(da^2 + db^2)
double flip_max_color_distance();                               // HyAB of Hunt(green) and Hunt(blue)
// The color error in [0,1] of a HyAB distance: compress by ^0.7, then the paper's two-segment map
// (pc = 0.4 of the maximum maps to pt = 0.95).
double flip_color_remap(double hyab_distance);

}  // namespace pxf
