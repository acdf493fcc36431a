// Helpers of the bilateral-grid shaders (grid_*.comp, grid_slice.frag). Mirrors gl/grid_layout.h
// and gl/grid_reference.cpp: keep them in step.
const int kGridRangeCells = 40;  // kGridRangeCells in gl/grid_layout.h

// Bounds of the guide's luminance, as float bits (non-negative floats order like their bits).
layout(std430, binding = 4) buffer GridBounds { uint y_min_bits; uint y_max_bits; };

// The range coordinate: luminance of the cleaned range color, negative values read as 0.
float guide_luminance(vec4 g) { return max(luminance(clean(g.rgb)), 0.0); }

// z of a luminance: (Y - Y_min) / cell_z with cell_z = grid_cell_z(Y_min, Y_max, sigma_c), i.e.
// min_cell_z = grid_min_cell_z(sigma_c) stretched to the span.
float grid_z(float y, float min_cell_z) {
  float y_min = uintBitsToFloat(y_min_bits), y_max = uintBitsToFloat(y_max_bits);
  float cell_z = max(min_cell_z, (y_max - y_min) / float(kGridRangeCells - 1));
  return clamp((y - y_min) / cell_z, 0.0, float(kGridRangeCells - 1));
}

// The grid blur's taps (kGridBlurRadius, kGridBlurTaps in gl/grid_layout.h).
const int kGridBlurRadius = 1;
const float kGridBlurTaps[3] = float[3](0.25, 0.5, 0.25);

// grid_interpolation_correction() of gl/grid_layout.h.
float grid_interpolation_correction(float a) {
  const float g0 = 6.0 / 16.0, g1 = 4.0 / 16.0;
  float b = 1.0 - a;
  return 1.0 + 2.0 * a * b * g1 / (g0 * (a * a + b * b));
}

// Nearest cell of a grid coordinate (cell centers at integers).
int nearest_cell(float u) { return int(floor(u + 0.5)); }
