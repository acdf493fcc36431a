// Writes linear RGB environment maps as OpenEXR (half floats, ZIP compression).
#pragma once
#include <string>

#include "texture.h"

namespace pxf::scenegen {

// `rgb` must have 3 channels; values are clamped to the half-float range. False + message on error.
bool writeExrRgb(const std::string& path, const FloatImage& rgb, std::string* error);

}  // namespace pxf::scenegen
