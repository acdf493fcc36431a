// Cell layout of the bilateral-grid filter (FilterKind::Grid; Chen, Paris and Durand 2007), shared
// by the GL pass (gl/grid_filter.cpp, shaders/grid_*.comp, shaders/grid_slice.frag) and its CPU
// reference (gl/grid_reference.cpp). No GL here.
//
// The grid is 3D: pixel x, pixel y and one range coordinate z, the luminance Y of the range
// color. Cell centers sit at integer grid coordinates: pixel (x, y) of luminance Y lies at
// (x / cell_s, y / cell_s, (Y - Y_min) / cell_z). Why luminance alone: a 4D grid (adding the
// distance) or a 5D one (RGB) multiplies the cells to blur and the corners to slice (16 or 32
// instead of 8) and would not fit the budget on llvmpipe. What it gives up against the exact
// RGB + depth weight: two neighbouring surfaces whose range colors have the same luminance (a
// chroma edge) or that lie at different distances with the same luminance are mixed. In the range
// buffer the luminance already carries the shading term (0.2 + 0.8 n.v), so most geometric
// edges (a change of normal) still separate.
#pragma once
#include <algorithm>
#include <cmath>
#include "gl/pass_params.h"

namespace pxf {

// Cells are kGridCellPerSigma sigmas wide, in x and y (sigma_s) and in z (sigma_c). The effective
// kernel along an axis is the nearest-cell splat (a box: variance 1/12 cell^2), the blur (1/2 cell^2)
// and the slice's linear interpolation (a tent: 1/6 cell^2), 3/4 cell^2 in all, i.e. a standard
// deviation of 1.08 sigma at 1.25 (the 5-tap blur on cells of one sigma gave 1.12 sigma, with 2.9x
// the blur work: 1.8x the cells, 5 taps instead of 3).
constexpr float kGridCellPerSigma = 1.25f;
// Range cells along z: kGridRangeCells (shaders/pass_formulas.h, which the shaders share). The range
// color's luminance spans [0, 1] (albedo x shading), i.e. 40 cells at the default sigma_c = 0.02; a
// wider span stretches the cells (cell_z grows) instead of growing the grid, which widens the range
// kernel proportionally. The blur's taps and the slice's variance correction are there too.
using shared::grid_interpolation_correction;
using shared::kGridBlurRadius;
using shared::kGridBlurTaps;
using shared::kGridRangeCells;
// Spatial cells are at least this wide: below it the grid would have more cells than the image has
// pixels, and the exact kernel is cheap anyway.
constexpr float kGridMinCellPx = 4.0f;

struct GridLayout {
  int nx = 2, ny = 2, nz = kGridRangeCells;
  float cell_s = kGridMinCellPx;  // pixels per spatial cell
  size_t cells() const { return size_t(nx) * ny * nz; }
};

// Cells 0 .. floor((W-1)/cell_s) + 1 in x: every pixel's coordinate u lies in [0, nx - 1) so
// that the slice's corners floor(u) and floor(u) + 1 both exist (same in y).
inline GridLayout grid_layout(int width, int height, const FilterParams& p) {
  GridLayout g;
  g.cell_s = std::max(p.sigma_s * kGridCellPerSigma, kGridMinCellPx);
  g.nx = static_cast<int>(std::floor(float(std::max(width, 1) - 1) / g.cell_s)) + 2;
  g.ny = static_cast<int>(std::floor(float(std::max(height, 1) - 1) / g.cell_s)) + 2;
  return g;
}

// Smallest range cell: kGridCellPerSigma sigma_c (the shaders get it as a uniform).
inline float grid_min_cell_z(float sigma_c) { return std::max(sigma_c * kGridCellPerSigma, 1.0e-6f); }

// Range cell size from the guide's luminance span [y_min, y_max]: grid_min_cell_z, stretched so that
// the span fits the kGridRangeCells cells (z in [0, nz - 1]).
inline float grid_cell_z(float y_min, float y_max, float sigma_c) {
  return shared::grid_cell_z(y_min, y_max, grid_min_cell_z(sigma_c));
}

}  // namespace pxf
