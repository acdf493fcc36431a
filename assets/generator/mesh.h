// Procedural triangle meshes for the built-in scenes: positions, normals, UVs and indices.
#pragma once
#include <glm/glm.hpp>
#include <cstdint>
#include <functional>
#include <vector>

namespace pxf::scenegen {

struct MeshData {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;
  std::vector<glm::vec2> uvs;
  std::vector<uint32_t> indices;  // triangles, counter-clockwise seen from the front

  size_t triangle_count() const { return indices.size() / 3; }
  // Appends `other` transformed by `transform` (normals by its inverse transpose).
  void append(const MeshData& other, const glm::mat4& transform = glm::mat4(1.0f));
};

// A rectangle spanned by `edge_u` and `edge_v` from `corner`; its front faces cross(edge_u, edge_v).
// UVs run 0..uv_scale.x along edge_u and 0..uv_scale.y along edge_v (v = 0 at the corner + edge_v side
// so that textures appear upright when edge_v points up).
MeshData make_quad(const glm::vec3& corner, const glm::vec3& edge_u, const glm::vec3& edge_v,
                   glm::vec2 uv_scale = glm::vec2(1.0f));

// An axis-aligned box with outward faces; UVs in meters times uv_per_meter (world-scaled textures).
MeshData make_box(const glm::vec3& min_corner, const glm::vec3& max_corner, float uv_per_meter = 1.0f);

// A UV sphere with smooth normals: `segments` around the equator, `rings` pole to pole.
MeshData make_sphere(const glm::vec3& center, float radius, int segments, int rings);

// A capped cylinder along +Y from y0 to y1 (smooth side normals, flat caps).
MeshData make_cylinder(const glm::vec3& base_center, float radius, float height, int segments,
                       bool cap_top = true, bool cap_bottom = true);

// A surface of revolution around +Y through the profile points (radius, y), bottom to top.
// Normals come from the profile's tangents, so lathed bowls and bottles look smooth; a point
// given twice in a row makes a sharp crease there.
MeshData make_lathe(const std::vector<glm::vec2>& profile, int segments, float uv_per_meter = 1.0f);

// A tube of circular cross-section swept along a closed curve `center(t)`, t in [0, 1).
// `radial_offset(t, phi)` displaces the surface along its normal (0 for a plain tube);
// normals are recomputed from the displaced grid so that bumps shade correctly.
MeshData make_swept_tube(const std::function<glm::vec3(float)>& center, float radius, int length_segments,
                         int radial_segments, glm::vec2 uv_repeat,
                         const std::function<float(float, float)>& radial_offset = nullptr);

// One vertex of a parametric surface: position, normal (need not be unit length) and UV.
struct SurfacePoint {
  glm::vec3 position;
  glm::vec3 normal;
  glm::vec2 uv;
};

// A (cols + 1) x (rows + 1) grid of `point(u, v)`, u and v in [0, 1]; each triangle is wound to
// agree with the normals, and zero-area ones (a pole, a fan's centre) are dropped.
MeshData make_surface(int cols, int rows, const std::function<SurfacePoint(float, float)>& point);

// A flat disc in the XZ plane facing +Y.
MeshData make_disc(const glm::vec3& center, float radius, int segments, float uv_per_meter = 1.0f);

// A half-round arch (extruded along Z) spanning x in [-half_span, half_span], springing at y = 0:
// the intrados (underside) and the soffit between the two faces, plus the spandrel walls that
// fill the rectangle up to `top_y`. Used for colonnades.
MeshData make_arch_wall(float half_span, float top_y, float depth, int segments, float uv_per_meter);

}  // namespace pxf::scenegen
