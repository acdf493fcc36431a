// Helpers of the bilateral-grid shaders (grid_*.comp, grid_slice.frag). Mirrors gl/grid_layout.h
// and gl/grid_reference.cpp: keep them in step.
const int kGridRangeCells = 48;  // kGridRangeCells in gl/grid_layout.h

// Bounds of the guide's luminance, as float bits (non-negative floats order like their bits).
layout(std430, binding = 4) buffer GridBounds { uint y_min_bits; uint y_max_bits; };

// The range coordinate: luminance of the cleaned range color, negative values read as 0.
float guide_luminance(vec4 g) { return max(luminance(clean(g.rgb)), 0.0); }

// z of a luminance: (Y - Y_min) / cell_z with cell_z = grid_cell_z(Y_min, Y_max, sigma_c).
float grid_z(float y, float sigma_c) {
  float y_min = uintBitsToFloat(y_min_bits), y_max = uintBitsToFloat(y_max_bits);
  float cell_z = max(max(sigma_c, 1.0e-6), (y_max - y_min) / float(kGridRangeCells - 1));
  return clamp((y - y_min) / cell_z, 0.0, float(kGridRangeCells - 1));
}

// The grid blur's taps (kGridBlurTaps in gl/grid_layout.h).
const float kGridBlurTaps[5] = float[5](1.0 / 16.0, 4.0 / 16.0, 6.0 / 16.0, 4.0 / 16.0, 1.0 / 16.0);

// Nearest cell of a grid coordinate (cell centers at integers).
int nearest_cell(float u) { return int(floor(u + 0.5)); }
