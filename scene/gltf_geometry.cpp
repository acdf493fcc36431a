#include "scene/gltf_geometry.h"

#include <cmath>

namespace pxf::gltf {

bool is_finite(glm::vec2 v) { return std::isfinite(v.x) && std::isfinite(v.y); }
bool is_finite(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
bool is_finite(glm::vec4 v) { return is_finite(glm::vec3(v)) && std::isfinite(v.w); }

glm::vec3 any_orthogonal(glm::vec3 n) {
  // Branchless orthonormal basis (Duff et al. 2017).
  float sign = std::copysign(1.0f, n.z);
  float a = -1.0f / (sign + n.z);
  float b = n.x * n.y * a;
  return glm::vec3(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
}

namespace {

// A triangle is degenerate when its area is zero relative to its size: this catches repeated and
// collinear vertices without rejecting small but well-shaped triangles at any scene scale.
bool is_degenerate(glm::vec3 a, glm::vec3 b, glm::vec3 c) {
  // In double: in float the cross product overflows for edges above ~1e9 units and underflows
  // below ~1e-10, which dropped whole scenes at those scales.
  const glm::dvec3 e1 = glm::dvec3(b) - glm::dvec3(a), e2 = glm::dvec3(c) - glm::dvec3(a);
  const double twice_area = glm::length(glm::cross(e1, e2));
  const double scale = std::max(glm::dot(e1, e1), glm::dot(e2, e2));
  return !(twice_area > 1e-7 * scale) || !std::isfinite(twice_area);
}

}  // namespace

void drop_invalid_triangles(Mesh& mesh, DroppedTriangles& dropped) {
  std::vector<glm::uvec3> kept;
  kept.reserve(mesh.triangles.size());
  std::vector<bool> used(mesh.positions.size(), false);
  for (const glm::uvec3& t : mesh.triangles) {
    glm::vec3 a = mesh.positions[t.x], b = mesh.positions[t.y], c = mesh.positions[t.z];
    if (!is_finite(a) || !is_finite(b) || !is_finite(c)) {
      ++dropped.nonfinite;
    } else if (is_degenerate(a, b, c)) {
      ++dropped.degenerate;
    } else {
      kept.push_back(t);
      used[t.x] = used[t.y] = used[t.z] = true;
    }
  }
  mesh.triangles = std::move(kept);
  for (size_t i = 0; i < mesh.positions.size(); ++i)
    if (!used[i] && !is_finite(mesh.positions[i])) mesh.positions[i] = glm::vec3(0.0f);
}

std::vector<glm::vec3> area_weighted_normals(const Mesh& mesh) {
  std::vector<glm::vec3> sum(mesh.positions.size(), glm::vec3(0.0f));
  for (const glm::uvec3& t : mesh.triangles) {
    // The unnormalized cross product is twice the area times the face normal.
    glm::vec3 n = glm::cross(mesh.positions[t.y] - mesh.positions[t.x], mesh.positions[t.z] - mesh.positions[t.x]);
    sum[t.x] += n;
    sum[t.y] += n;
    sum[t.z] += n;
  }
  for (glm::vec3& n : sum) {
    float len = glm::length(n);
    n = (len > 0.0f && std::isfinite(len)) ? n / len : glm::vec3(0.0f, 0.0f, 1.0f);
  }
  return sum;
}

void sanitize_normals(Mesh& mesh, const std::vector<glm::vec3>& fallback) {
  mesh.normals.resize(mesh.positions.size(), glm::vec3(0.0f));
  for (size_t i = 0; i < mesh.normals.size(); ++i) {
    glm::vec3 n = mesh.normals[i];
    float len = glm::length(n);
    mesh.normals[i] = (len > 1e-20f && std::isfinite(len)) ? n / len : fallback[i];
  }
}

std::vector<glm::vec4> compute_tangents(const Mesh& mesh, const std::vector<glm::vec2>& uvs) {
  size_t n = mesh.positions.size();
  std::vector<glm::vec3> tangent_sum(n, glm::vec3(0.0f)), bitangent_sum(n, glm::vec3(0.0f));
  if (uvs.size() == n) {
    for (const glm::uvec3& t : mesh.triangles) {
      glm::vec3 e1 = mesh.positions[t.y] - mesh.positions[t.x];
      glm::vec3 e2 = mesh.positions[t.z] - mesh.positions[t.x];
      glm::vec2 d1 = uvs[t.y] - uvs[t.x], d2 = uvs[t.z] - uvs[t.x];
      float det = d1.x * d2.y - d2.x * d1.y;
      if (!(std::fabs(det) > 1e-20f) || !std::isfinite(det)) continue;  // degenerate UVs
      // dP/du and dP/dv; weighting by the unnormalized derivatives (area-like) as MikkTSpace's
      // simple variant does.
      float r = 1.0f / det;
      glm::vec3 dpdu = (e1 * d2.y - e2 * d1.y) * r;
      glm::vec3 dpdv = (e2 * d1.x - e1 * d2.x) * r;
      if (!is_finite(dpdu) || !is_finite(dpdv)) continue;
      float weight = glm::length(glm::cross(e1, e2));
      glm::vec3 du = glm::length(dpdu) > 0 ? glm::normalize(dpdu) * weight : glm::vec3(0.0f);
      glm::vec3 dv = glm::length(dpdv) > 0 ? glm::normalize(dpdv) * weight : glm::vec3(0.0f);
      for (uint32_t v : {t.x, t.y, t.z}) {
        tangent_sum[v] += du;
        bitangent_sum[v] += dv;
      }
    }
  }
  std::vector<glm::vec4> tangents(n);
  for (size_t i = 0; i < n; ++i) {
    glm::vec3 normal = i < mesh.normals.size() ? mesh.normals[i] : glm::vec3(0, 0, 1);
    glm::vec3 t = tangent_sum[i] - normal * glm::dot(normal, tangent_sum[i]);
    float len = glm::length(t);
    if (!(len > 1e-12f) || !std::isfinite(len)) {
      tangents[i] = glm::vec4(any_orthogonal(normal), 1.0f);
      continue;
    }
    t /= len;
    // glTF v runs down the image, so the normal map's "up" (+green) is -dP/dv.
    float w = glm::dot(glm::cross(normal, t), -bitangent_sum[i]) < 0.0f ? -1.0f : 1.0f;
    tangents[i] = glm::vec4(t, w);
  }
  return tangents;
}

void sanitize_tangents(Mesh& mesh) {
  mesh.tangents.resize(mesh.positions.size(), glm::vec4(0.0f));
  for (size_t i = 0; i < mesh.tangents.size(); ++i) {
    glm::vec3 normal = mesh.normals[i];
    glm::vec4 t4 = mesh.tangents[i];
    glm::vec3 t = glm::vec3(t4) - normal * glm::dot(normal, glm::vec3(t4));
    float len = glm::length(t);
    float w = (std::isfinite(t4.w) && t4.w < 0.0f) ? -1.0f : 1.0f;
    mesh.tangents[i] = (len > 1e-12f && std::isfinite(len)) ? glm::vec4(t / len, w)
                                                             : glm::vec4(any_orthogonal(normal), w);
  }
}

}  // namespace pxf::gltf
