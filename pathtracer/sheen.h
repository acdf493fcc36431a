// The sheen lobe of KHR_materials_sheen: the Charlie distribution with Estevez and Kulla's (2017)
// visibility, as the extension and the Khronos sample viewer define them, and its directional albedo tabulated over (cos theta_o, sheen
// roughness) for the extension's albedo scaling of the layers below (sheen_albedo_table.inc,
// written by tools/make_albedo_table.cpp sheen; docs/materials.md).
#pragma once

namespace pxf {

constexpr int kSheenAlbedoSize = 32;  // table points along cos theta_o and along sheen roughness
// The Charlie distribution concentrates at grazing half vectors as alpha falls; below this it is
// too sharp for the table's quadrature, and visually the same.
constexpr float kMinSheenAlpha = 0.01f;

// alpha = max(sheen roughness^2, kMinSheenAlpha) (the extension's mapping, floored).
inline float sheen_alpha(float sheen_roughness) {
  const float a = sheen_roughness * sheen_roughness;
  return a > kMinSheenAlpha ? a : kMinSheenAlpha;
}

// D(h) = (2 + 1/alpha) sin(theta_h)^(1/alpha) / (2 pi), normalized: integral D cos theta_h = 1.
float charlie_d(float cos_h, float alpha);
// Estevez and Kulla's V = 1 / ((1 + Lambda(cos_o) + Lambda(cos_i)) 4 cos_o cos_i), clamped to [0, 1],
// Lambda their fitted curve; f = color D V. (Neubelt and Pettineo's simpler 1 / (4 (cos_i + cos_o -
// cos_i cos_o)), which the extension also names, reflects up to 4x the light at grazing angles.)
float sheen_visibility(float cos_o, float cos_i, float alpha);

// The albedo of f = D V (color 1) at cos_o: a midpoint grid of n x n/2 over the hemisphere (cos
// theta x phi, phi over [0, pi] by symmetry). The generator's.
float sheen_albedo_quadrature(float cos_o, float alpha, int n);
// The table's grid: column j at cos theta_o = (j / (kSheenAlbedoSize - 1))^2 (as ggx_albedo.h's),
// row i at sheen roughness sqrt(kMinSheenAlpha) + (1 - sqrt(kMinSheenAlpha)) i / (kSheenAlbedoSize - 1),
// so that the first row is the floor and no two rows share an alpha.
float sheen_table_roughness(int row);
// Bilinear lookup in the generated table.
float sheen_albedo(float cos_o, float alpha);
float sheen_albedo_table_entry(int roughness_index, int cos_index);

}  // namespace pxf
