// The bilateral grid's Var[L_f]. Every pixel i lands, with weight 1, in its nearest cell c(i); the
// blur g (separable, three axes) and the slice's interpolation weights a_j make L_f a linear
// combination sum_i W_i L_i / sum_i W_i with W_i = sum_j a_j g(j - c(i)) (j: the 8 slice corners).
// The exact variance of that is sum_i W_i^2 Var_i / (sum_i W_i)^2. What is propagated instead is
// what linear operations on the cells give when each cell is taken as independent of the others:
// the cells hold sum Var_i (weight 1 squared), the blur weights them by g^2, the slice by a_j^2:
//   sum_j a_j^2 sum_c g(j - c)^2 sum_{i in c} Var_i,
// which drops the cross terms 2 a_j a_k g(j - c) g(k - c) of the exact sum: two corners of the slice
// share pixels through the blur. Along each spatial axis that omission is corrected by the factor
// grid_interpolation_correction(a) (shaders/pass_formulas.h), exact for uniformly occupied cells of
// uniform variance (a flat guide: Grid.WhiteNoiseVarianceMatchesExactSum checks it). Along z it is
// corrected by grid_range_correction(a_z), exact when the pixels that matter lie in the pixel's own
// range cell (a surface of one range colour between two range cells: checked by the same test).
// Not corrected: non-uniform occupancy.
// Unknown variances (n < 2, or 0) count with the weighted mean of the known ones, as in the
// other variants.
#include "gl/grid_reference.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>
#include "gl/grid_layout.h"

namespace pxf {
namespace {

using Cell = std::array<float, 8>;  // a = (sum L rgb, count), b = (sum Var, unknown, known, sum Var)

struct Grid {
  GridLayout layout;
  float y_min = 0, cell_z = 1;
  std::vector<Cell> cells;
  size_t index(int i, int j, int k) const { return (size_t(k) * layout.ny + j) * layout.nx + i; }
};

using shared::nearest_cell;

float guide_luminance(const Image& range_color, int x, int y) {
  return shared::guide_luminance(glm::vec4(range_color.at(x, y, 0), range_color.at(x, y, 1), range_color.at(x, y, 2), 0.0f));
}
float grid_z(const Grid& g, float y) { return shared::grid_z(y, g.y_min, g.cell_z); }

// c += w x (value sums), w^2 x (squared-weight sums b.xy).
void add_weighted(Cell& c, const Cell& src, float w) {
  for (int m = 0; m < 8; ++m) c[m] += (m == 4 || m == 5 ? w * w : w) * src[m];
}

Grid splat(const Image& hv, const Image& var_u, const Image& range_color, const FilterParams& p) {
  Grid g;
  g.layout = grid_layout(hv.width, hv.height, p);
  float y_min = 3.0e38f, y_max = 0.0f;
  for (int y = 0; y < hv.height; ++y)
    for (int x = 0; x < hv.width; ++x) {
      y_min = std::min(y_min, guide_luminance(range_color, x, y));
      y_max = std::max(y_max, guide_luminance(range_color, x, y));
    }
  g.y_min = y_min;
  g.cell_z = grid_cell_z(y_min, y_max, p.sigma_c);
  g.cells.assign(g.layout.cells(), Cell{});
  const float inv_cell_s = 1.0f / g.layout.cell_s;
  for (int y = 0; y < hv.height; ++y)
    for (int x = 0; x < hv.width; ++x) {
      const int k = std::clamp(nearest_cell(grid_z(g, guide_luminance(range_color, x, y))), 0, kGridRangeCells - 1);
      const float var = clean_var(var_u.at(x, y, 0));
      const Cell pixel = var > 0.0f ? Cell{clean(hv.at(x, y, 0)), clean(hv.at(x, y, 1)), clean(hv.at(x, y, 2)), 1.0f,
                                           var, 0.0f, 1.0f, var}
                                    : Cell{clean(hv.at(x, y, 0)), clean(hv.at(x, y, 1)), clean(hv.at(x, y, 2)), 1.0f,
                                           0.0f, 1.0f, 0.0f, 0.0f};
      // The z pass of the blur, per pixel (as grid_splat.comp does).
      for (int t = 0; t <= 2 * kGridBlurRadius; ++t) {
        const int q = k + t - kGridBlurRadius;
        if (q < 0 || q >= kGridRangeCells) continue;
        Cell& c = g.cells[g.index(nearest_cell(float(x) * inv_cell_s), nearest_cell(float(y) * inv_cell_s), q)];
        add_weighted(c, pixel, kGridBlurTaps[t]);
      }
    }
  return g;
}

// One axis of the blur: value sums (a, b.zw) with the taps g, squared-weight sums (b.xy) with g^2.
void blur(Grid& g, int axis) {
  const GridLayout& l = g.layout;
  std::vector<Cell> out(g.cells.size());
  const int n[3] = {l.nx, l.ny, l.nz};
  for (int k = 0; k < l.nz; ++k)
    for (int j = 0; j < l.ny; ++j)
      for (int i = 0; i < l.nx; ++i) {
        const int c[3] = {i, j, k};
        Cell sum{};
        for (int t = 0; t <= 2 * kGridBlurRadius; ++t) {
          int q[3] = {i, j, k};
          q[axis] = c[axis] + t - kGridBlurRadius;
          if (q[axis] < 0 || q[axis] >= n[axis]) continue;
          add_weighted(sum, g.cells[g.index(q[0], q[1], q[2])], kGridBlurTaps[t]);
        }
        out[g.index(i, j, k)] = sum;
      }
  g.cells = std::move(out);
}

// Trilinear slice at the pixel's own grid coordinates (see the comment at the top of the file).
// The centre weight: the pixel's own effective weight W_i = sum_j a_j g(j - c(i)) over the corners j
// (c(i) its nearest cell: the cell its splat went to) over sum_i W_i, the interpolated count.
void slice(const Grid& g, int x, int y, float luminance_y, FilterOutput& out) {
  const float inv_cell_s = 1.0f / g.layout.cell_s;
  const float u = float(x) * inv_cell_s, v = float(y) * inv_cell_s, z = grid_z(g, luminance_y);
  const int c0[3] = {static_cast<int>(std::floor(u)), static_cast<int>(std::floor(v)),
                     std::min(static_cast<int>(std::floor(z)), kGridRangeCells - 2)};
  const float frac[3] = {std::clamp(u - c0[0], 0.0f, 1.0f), std::clamp(v - c0[1], 0.0f, 1.0f),
                         std::clamp(z - c0[2], 0.0f, 1.0f)};
  const int own[3] = {nearest_cell(u), nearest_cell(v), std::clamp(nearest_cell(z), 0, kGridRangeCells - 1)};
  Cell sum{};
  float own_weight = 0.0f;
  for (int dz = 0; dz < 2; ++dz)
    for (int dy = 0; dy < 2; ++dy)
      for (int dx = 0; dx < 2; ++dx) {
        const float w = (dx ? frac[0] : 1.0f - frac[0]) * (dy ? frac[1] : 1.0f - frac[1]) * (dz ? frac[2] : 1.0f - frac[2]);
        const Cell& c = g.cells[g.index(c0[0] + dx, c0[1] + dy, c0[2] + dz)];
        add_weighted(sum, c, w);
        own_weight += w * shared::grid_blur_tap(c0[0] + dx - own[0]) * shared::grid_blur_tap(c0[1] + dy - own[1]) *
                      shared::grid_blur_tap(c0[2] + dz - own[2]);
      }
  out.centre_weight.at(x, y, 0) = own_weight / sum[3];
  // sum[3] > 0: the pixel's own nearest cell is a corner with weight >= 1/2 per axis.
  for (int ch = 0; ch < 3; ++ch) out.filtered.at(x, y, ch) = sum[ch] / sum[3];
  const float correction = grid_interpolation_correction(frac[0]) * grid_interpolation_correction(frac[1]) *
                           shared::grid_range_correction(frac[2], c0[2], own[2]);
  out.variance.at(x, y, 0) = shared::propagated_variance(sum[3], sum[4], sum[5], sum[6], sum[7], correction);
}

}  // namespace

FilterOutput cpu_grid_filter(const Image& hv, const Image& var_u, const Image& lv, const Image& range_color,
                             const Image& depth, const FilterParams& p, float t, const Image* surface,
                             const Image* half_variances) {
  Grid g = splat(hv, var_u, range_color, p);
  for (int axis = 0; axis < 2; ++axis) blur(g, axis);  // z: in the splat
  FilterOutput out{Image::rgb(hv.width, hv.height), Image::gray(hv.width, hv.height),
                   Image::gray(hv.width, hv.height, "Y", 1.0f)};  // centre weight 1 where skipped
  for (int y = 0; y < hv.height; ++y)
    for (int x = 0; x < hv.width; ++x) {
      if (p.skip_case2 && skip_as_case2(hv, var_u, lv, range_color, depth, p, t, x, y, out, surface, half_variances))
        continue;
      slice(g, x, y, guide_luminance(range_color, x, y), out);
    }
  return out;
}

}  // namespace pxf
