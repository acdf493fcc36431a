#include "mesh.h"

#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_inverse.hpp>

namespace pxf::scenegen {
namespace {

constexpr float kTwoPi = glm::two_pi<float>();

// Adds the two triangles of the quad a-b-c-d (in order around it), each wound so that its
// geometric normal agrees with the vertex normals; zero-area triangles (at poles) are dropped.
void add_quad_oriented(MeshData& mesh, uint32_t a, uint32_t b, uint32_t c, uint32_t d) {
  auto add_triangle = [&mesh](uint32_t i0, uint32_t i1, uint32_t i2) {
    const glm::vec3& p0 = mesh.positions[i0];
    glm::vec3 geometric = glm::cross(mesh.positions[i1] - p0, mesh.positions[i2] - p0);
    if (glm::dot(geometric, geometric) < 1e-20f) return;
    glm::vec3 shading = mesh.normals[i0] + mesh.normals[i1] + mesh.normals[i2];
    if (glm::dot(geometric, shading) < 0.0f) std::swap(i1, i2);
    mesh.indices.insert(mesh.indices.end(), {i0, i1, i2});
  };
  add_triangle(a, b, c);
  add_triangle(a, c, d);
}

// A (cols+1) x (rows+1) vertex grid; vertex(u, v) with u, v in [0, 1] fills one vertex.
template <typename VertexFn>
MeshData make_grid(int cols, int rows, VertexFn vertex) {
  MeshData mesh;
  for (int j = 0; j <= rows; ++j) {
    for (int i = 0; i <= cols; ++i) vertex(mesh, float(i) / float(cols), float(j) / float(rows));
  }
  for (int j = 0; j < rows; ++j) {
    for (int i = 0; i < cols; ++i) {
      uint32_t a = uint32_t(j * (cols + 1) + i);
      uint32_t b = a + 1;
      uint32_t c = b + uint32_t(cols + 1);
      uint32_t d = a + uint32_t(cols + 1);
      add_quad_oriented(mesh, a, b, c, d);
    }
  }
  return mesh;
}

void push_vertex(MeshData& mesh, const glm::vec3& p, const glm::vec3& n, const glm::vec2& uv) {
  mesh.positions.push_back(p);
  mesh.normals.push_back(glm::normalize(n));
  mesh.uvs.push_back(uv);
}

}  // namespace

void MeshData::append(const MeshData& other, const glm::mat4& transform) {
  const uint32_t base = uint32_t(positions.size());
  const glm::mat3 normal_matrix = glm::inverseTranspose(glm::mat3(transform));
  const bool mirrored = glm::determinant(glm::mat3(transform)) < 0.0f;
  for (size_t i = 0; i < other.positions.size(); ++i) {
    positions.push_back(glm::vec3(transform * glm::vec4(other.positions[i], 1.0f)));
    normals.push_back(glm::normalize(normal_matrix * other.normals[i]));
    uvs.push_back(other.uvs[i]);
  }
  for (size_t t = 0; t + 2 < other.indices.size(); t += 3) {
    uint32_t i0 = other.indices[t], i1 = other.indices[t + 1], i2 = other.indices[t + 2];
    if (mirrored) std::swap(i1, i2);  // a mirroring transform flips the winding
    indices.insert(indices.end(), {base + i0, base + i1, base + i2});
  }
}

MeshData make_quad(const glm::vec3& corner, const glm::vec3& edge_u, const glm::vec3& edge_v,
                   glm::vec2 uv_scale) {
  MeshData mesh;
  const glm::vec3 n = glm::normalize(glm::cross(edge_u, edge_v));
  push_vertex(mesh, corner, n, {0.0f, uv_scale.y});
  push_vertex(mesh, corner + edge_u, n, {uv_scale.x, uv_scale.y});
  push_vertex(mesh, corner + edge_u + edge_v, n, {uv_scale.x, 0.0f});
  push_vertex(mesh, corner + edge_v, n, {0.0f, 0.0f});
  mesh.indices = {0, 1, 2, 0, 2, 3};
  return mesh;
}

MeshData make_box(const glm::vec3& lo, const glm::vec3& hi, float uv_per_meter) {
  const glm::vec3 d = hi - lo;
  const float s = uv_per_meter;
  MeshData box;
  box.append(make_quad({hi.x, lo.y, hi.z}, {0, 0, -d.z}, {0, d.y, 0}, s * glm::vec2(d.z, d.y)));
  box.append(make_quad({lo.x, lo.y, lo.z}, {0, 0, d.z}, {0, d.y, 0}, s * glm::vec2(d.z, d.y)));
  box.append(make_quad({lo.x, lo.y, hi.z}, {d.x, 0, 0}, {0, d.y, 0}, s * glm::vec2(d.x, d.y)));
  box.append(make_quad({hi.x, lo.y, lo.z}, {-d.x, 0, 0}, {0, d.y, 0}, s * glm::vec2(d.x, d.y)));
  box.append(make_quad({lo.x, hi.y, hi.z}, {d.x, 0, 0}, {0, 0, -d.z}, s * glm::vec2(d.x, d.z)));
  box.append(make_quad({lo.x, lo.y, lo.z}, {d.x, 0, 0}, {0, 0, d.z}, s * glm::vec2(d.x, d.z)));
  return box;
}

MeshData make_sphere(const glm::vec3& center, float radius, int segments, int rings) {
  return make_grid(segments, rings, [&](MeshData& mesh, float u, float v) {
    const float phi = u * kTwoPi, theta = v * glm::pi<float>();
    glm::vec3 n(std::sin(theta) * std::cos(phi), std::cos(theta), -std::sin(theta) * std::sin(phi));
    push_vertex(mesh, center + radius * n, n, {u, v});
  });
}

MeshData make_cylinder(const glm::vec3& base, float radius, float height, int segments, bool cap_top,
                       bool cap_bottom) {
  const float circumference = kTwoPi * radius;
  MeshData mesh = make_grid(segments, 1, [&](MeshData& m, float u, float v) {
    const float phi = u * kTwoPi;
    glm::vec3 n(std::cos(phi), 0.0f, -std::sin(phi));
    push_vertex(m, base + radius * n + glm::vec3(0, (1.0f - v) * height, 0), n,
                {u * circumference, v * height});
  });
  if (cap_top) mesh.append(make_disc(base + glm::vec3(0, height, 0), radius, segments));
  if (cap_bottom) {
    // The bottom cap is the top disc turned upside down about its own center.
    glm::mat4 flip(1.0f);
    flip[1][1] = -1.0f;
    flip[3] = glm::vec4(0, 2.0f * base.y, 0, 1);
    mesh.append(make_disc(base, radius, segments), flip);
  }
  return mesh;
}

MeshData make_lathe(const std::vector<glm::vec2>& profile, int segments, float uv_per_meter) {
  const int rows = int(profile.size()) - 1;
  std::vector<float> arc_length(profile.size(), 0.0f);
  for (int j = 1; j <= rows; ++j)
    arc_length[j] = arc_length[j - 1] + glm::length(profile[j] - profile[j - 1]);
  MeshData mesh = make_grid(segments, rows, [&](MeshData& m, float u, float v) {
    const int j = int(std::lround(v * rows));
    // One-sided differences next to a repeated point, so repeated points make sharp creases.
    const int before = (j > 0 && profile[j - 1] != profile[j]) ? j - 1 : j;
    const int after = (j < rows && profile[j + 1] != profile[j]) ? j + 1 : j;
    const glm::vec2 prev = profile[before], next = profile[after];
    const glm::vec2 tangent = next - prev;  // (dr, dy) along the profile, bottom to top
    const float phi = u * kTwoPi;
    const glm::vec3 radial(std::cos(phi), 0.0f, -std::sin(phi));
    const glm::vec3 n = radial * tangent.y - glm::vec3(0, 1, 0) * tangent.x;
    const float r = profile[j].x;
    glm::vec3 normal = glm::dot(n, n) > 0.0f ? n : glm::vec3(0, tangent.y >= 0 ? -1 : 1, 0);
    push_vertex(m, radial * r + glm::vec3(0, profile[j].y, 0), normal,
                {u * kTwoPi * 0.1f * uv_per_meter, (arc_length[rows] - arc_length[j]) * uv_per_meter});
  });
  return mesh;
}

MeshData make_swept_tube(const std::function<glm::vec3(float)>& center, float radius, int length_segments,
                         int radial_segments, glm::vec2 uv_repeat,
                         const std::function<float(float, float)>& radial_offset) {
  const int cols = length_segments, rows = radial_segments;
  // Positions on the periodic grid (cols x rows), each with its undisplaced outward direction.
  std::vector<glm::vec3> grid(size_t(cols) * rows), outward(grid.size());
  for (int i = 0; i < cols; ++i) {
    const float t = float(i) / float(cols);
    const glm::vec3 p1 = center(t), p2 = center(t + 0.001f);
    // Frame as in the classic torus-knot construction: smooth for curves around the origin.
    const glm::vec3 tangent = p2 - p1;
    glm::vec3 normal = p2 + p1;
    const glm::vec3 binormal = glm::normalize(glm::cross(tangent, normal));
    normal = glm::normalize(glm::cross(binormal, tangent));
    for (int j = 0; j < rows; ++j) {
      const float phi = float(j) / float(rows) * kTwoPi;
      const glm::vec3 dir = -std::cos(phi) * normal + std::sin(phi) * binormal;
      const float offset = radial_offset ? radial_offset(t, phi) : 0.0f;
      grid[size_t(i) * rows + j] = p1 + (radius + offset) * dir;
      outward[size_t(i) * rows + j] = dir;
    }
  }
  auto at = [&](int i, int j) -> size_t { return size_t((i + cols) % cols) * rows + size_t((j + rows) % rows); };
  MeshData mesh = make_grid(cols, rows, [&](MeshData& m, float u, float v) {
    const int i = int(std::lround(u * cols)), j = int(std::lround(v * rows));
    const glm::vec3 du = grid[at(i + 1, j)] - grid[at(i - 1, j)];
    const glm::vec3 dv = grid[at(i, j + 1)] - grid[at(i, j - 1)];
    glm::vec3 n = glm::normalize(glm::cross(du, dv));
    if (glm::dot(n, outward[at(i, j)]) < 0.0f) n = -n;
    push_vertex(m, grid[at(i, j)], n, {u * uv_repeat.x, v * uv_repeat.y});
  });
  return mesh;
}

MeshData make_surface(int cols, int rows, const std::function<SurfacePoint(float, float)>& point) {
  return make_grid(cols, rows, [&](MeshData& mesh, float u, float v) {
    const SurfacePoint p = point(u, v);
    push_vertex(mesh, p.position, p.normal, p.uv);
  });
}

MeshData make_disc(const glm::vec3& center, float radius, int segments, float uv_per_meter) {
  MeshData mesh;
  const glm::vec3 up(0, 1, 0);
  push_vertex(mesh, center, up, glm::vec2(0.0f));
  for (int i = 0; i <= segments; ++i) {
    const float phi = float(i) / float(segments) * kTwoPi;
    const glm::vec3 offset(radius * std::cos(phi), 0.0f, -radius * std::sin(phi));
    push_vertex(mesh, center + offset, up, glm::vec2(offset.x, offset.z) * uv_per_meter);
    // Counter-clockwise seen from above: center, this rim vertex, the next one.
    if (i > 0) mesh.indices.insert(mesh.indices.end(), {0u, uint32_t(i), uint32_t(i + 1)});
  }
  return mesh;
}

MeshData make_arch_wall(float half_span, float top_y, float depth, int segments, float uv_per_meter) {
  // Boundary of the wall rectangle sampled so that its corners are exact samples: `side` samples
  // up each side and `across` along the top, matched one to one with arc points.
  const int side = std::max(1, int(std::lround(segments * top_y / (2.0f * top_y + 2.0f * half_span))));
  const int across = std::max(2, segments - 2 * side);
  const int n = 2 * side + across;
  auto boundary = [&](int k) -> glm::vec2 {
    if (k <= side) return {-half_span, top_y * float(k) / float(side)};
    if (k <= side + across) return {-half_span + 2.0f * half_span * float(k - side) / float(across), top_y};
    return {half_span, top_y * float(n - k) / float(side)};
  };
  auto arc = [&](int k) -> glm::vec2 {
    const float theta = glm::pi<float>() * (1.0f - float(k) / float(n));
    return {half_span * std::cos(theta), half_span * std::sin(theta)};
  };
  MeshData wall;
  const float s = uv_per_meter;
  for (float z_sign : {1.0f, -1.0f}) {
    MeshData face;
    const glm::vec3 normal(0, 0, z_sign);
    for (int k = 0; k <= n; ++k) {
      for (glm::vec2 p : {arc(k), boundary(k)}) {
        push_vertex(face, {p.x, p.y, z_sign * 0.5f * depth}, normal, {p.x * s * z_sign, (top_y - p.y) * s});
      }
    }
    for (int k = 0; k < n; ++k) {
      const uint32_t a = uint32_t(2 * k);
      add_quad_oriented(face, a, a + 1, a + 3, a + 2);
    }
    wall.append(face);
  }
  // The intrados: the curved underside, facing the opening.
  MeshData intrados = make_grid(n, 1, [&](MeshData& m, float u, float v) {
    const glm::vec2 p = arc(int(std::lround(u * n)));
    const float z = (v - 0.5f) * depth;
    push_vertex(m, {p.x, p.y, z}, -glm::vec3(p.x, p.y, 0.0f), {u * glm::pi<float>() * half_span * s, v * depth * s});
  });
  wall.append(intrados);
  wall.append(make_quad({-half_span, top_y, 0.5f * depth}, {2.0f * half_span, 0, 0}, {0, 0, -depth},
                        s * glm::vec2(2.0f * half_span, depth)));
  return wall;
}

}  // namespace pxf::scenegen
