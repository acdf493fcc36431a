// Geometry clean-up done once at load time, so the integrator and the raster pass can trust the
// mesh data: invalid triangles dropped, normals and tangents always unit length and finite.
#pragma once
#include <cstddef>
#include <vector>
#include <glm/glm.hpp>
#include "scene/scene.h"

namespace pxf::gltf {

struct DroppedTriangles {
  size_t nonfinite = 0;   // a vertex position is NaN or Inf
  size_t degenerate = 0;  // zero area (collinear or repeated vertices)
};

// Removes triangles with a non-finite vertex or zero area, then zeroes positions no triangle
// references any more (so no NaN remains in the mesh). Counts are added to `dropped`.
void drop_invalid_triangles(Mesh& mesh, DroppedTriangles& dropped);

// Area-weighted vertex normals (a non-indexed mesh thus gets flat normals). Vertices that belong
// to no triangle get (0, 0, 1).
std::vector<glm::vec3> area_weighted_normals(const Mesh& mesh);

// Renormalizes mesh.normals; zero or non-finite ones are replaced by `fallback` (same size).
void sanitize_normals(Mesh& mesh, const std::vector<glm::vec3>& fallback);

// MikkTSpace-style per-vertex tangents from the UV set `uvs` (per-triangle UV derivatives
// accumulated per vertex, Gram-Schmidt against the normal). Handedness w follows glTF:
// bitangent = cross(normal, tangent.xyz) * w points towards decreasing v (glTF's v runs down the
// image, normal-map green runs up). Degenerate UVs get any tangent orthogonal to the normal.
std::vector<glm::vec4> compute_tangents(const Mesh& mesh, const std::vector<glm::vec2>& uvs);

// Makes every tangent unit length, orthogonal to its normal and w = +-1; unusable ones are
// replaced by an arbitrary orthonormal tangent. Requires sanitized normals.
void sanitize_tangents(Mesh& mesh);

// Any unit vector orthogonal to unit vector n.
glm::vec3 any_orthogonal(glm::vec3 n);

bool is_finite(glm::vec2 v);
bool is_finite(glm::vec3 v);
bool is_finite(glm::vec4 v);

}  // namespace pxf::gltf
