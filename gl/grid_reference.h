// CPU reference of the bilateral-grid filter (FilterKind::Grid): the same cell layout
// (gl/grid_layout.h), splat, blur and slice as the GL pass (gl/grid_filter.cpp), in float and in
// the same summation order, so the two agree to float rounding. Its range axis is the guide's
// luminance: the surface terms (sigma_n, sigma_r) reach only its case-2 skip, not its kernel.
#pragma once
#include "gl/cpu_reference.h"

namespace pxf {

FilterOutput cpu_grid_filter(const Image& hv, const Image& var_u, const Image& lv, const Image& range_color,
                             const Image& depth, const FilterParams& params, float t,
                             const Image* surface = nullptr, const Image* half_variances = nullptr);

}  // namespace pxf
