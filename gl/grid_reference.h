// CPU reference of the bilateral-grid filter (FilterKind::Grid): the same cell layout
// (gl/grid_layout.h), splat, blur and slice as the GL pass (gl/grid_filter.cpp), in float and in
// the same summation order, so the two agree to float rounding.
#pragma once
#include "gl/cpu_reference.h"

namespace pxf {

FilterOutput cpu_grid_filter(const Image& hv, const Image& var_u, const Image& lv, const Image& range_color,
                             const Image& depth, const FilterParams& params, float t);

}  // namespace pxf
