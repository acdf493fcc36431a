// Helpers of the bilateral-grid shaders (grid_*.comp, grid_slice.frag) that read the grid's
// bounds; the grid's formulas and constants are in pass_formulas.h.

// Bounds of the guide's luminance, as float bits (non-negative floats order like their bits).
layout(std430, binding = kBufferGridBounds) buffer GridBounds { uint y_min_bits; uint y_max_bits; };

// z of a luminance with cell_z = grid_cell_z(Y_min, Y_max, min_cell_z) over the bounds found so far.
float grid_z(float y, float min_cell_z) {
  float y_min = uintBitsToFloat(y_min_bits), y_max = uintBitsToFloat(y_max_bits);
  return grid_z(y, y_min, grid_cell_z(y_min, y_max, min_cell_z));
}
