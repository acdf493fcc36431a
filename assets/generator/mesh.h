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

  size_t triangleCount() const { return indices.size() / 3; }
  // Appends `other` transformed by `transform` (normals by its inverse transpose).
  void append(const MeshData& other, const glm::mat4& transform = glm::mat4(1.0f));
};

// A rectangle spanned by `edgeU` and `edgeV` from `corner`; its front faces cross(edgeU, edgeV).
// UVs run 0..uvScale.x along edgeU and 0..uvScale.y along edgeV (v = 0 at the corner + edgeV side
// so that textures appear upright when edgeV points up).
MeshData makeQuad(const glm::vec3& corner, const glm::vec3& edgeU, const glm::vec3& edgeV,
                  glm::vec2 uvScale = glm::vec2(1.0f));

// An axis-aligned box with outward faces; UVs in meters times uvPerMeter (world-scaled textures).
MeshData makeBox(const glm::vec3& minCorner, const glm::vec3& maxCorner, float uvPerMeter = 1.0f);

// A UV sphere with smooth normals: `segments` around the equator, `rings` pole to pole.
MeshData makeSphere(const glm::vec3& center, float radius, int segments, int rings);

// A capped cylinder along +Y from y0 to y1 (smooth side normals, flat caps).
MeshData makeCylinder(const glm::vec3& baseCenter, float radius, float height, int segments,
                      bool capTop = true, bool capBottom = true);

// A surface of revolution around +Y through the profile points (radius, y), bottom to top.
// Normals come from the profile's tangents, so lathed bowls and bottles look smooth; a point
// given twice in a row makes a sharp crease there.
MeshData makeLathe(const std::vector<glm::vec2>& profile, int segments, float uvPerMeter = 1.0f);

// A tube of circular cross-section swept along a closed curve `center(t)`, t in [0, 1).
// `radialOffset(t, phi)` displaces the surface along its normal (0 for a plain tube);
// normals are recomputed from the displaced grid so that bumps shade correctly.
MeshData makeSweptTube(const std::function<glm::vec3(float)>& center, float radius, int lengthSegments,
                       int radialSegments, glm::vec2 uvRepeat,
                       const std::function<float(float, float)>& radialOffset = nullptr);

// A flat disc in the XZ plane facing +Y.
MeshData makeDisc(const glm::vec3& center, float radius, int segments, float uvPerMeter = 1.0f);

// A half-round arch (extruded along Z) spanning x in [-halfSpan, halfSpan], springing at y = 0:
// the intrados (underside) and the soffit between the two faces, plus the spandrel walls that
// fill the rectangle up to `topY`. Used for colonnades.
MeshData makeArchWall(float halfSpan, float topY, float depth, int segments, float uvPerMeter);

}  // namespace pxf::scenegen
