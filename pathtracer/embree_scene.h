// The scene's triangles in an Embree 3 BVH, plus the per-triangle data the integrator needs at a
// hit (face normal, interpolated attributes). Alpha MASK materials are cut out by Embree filter
// functions, so every query (camera, continuation, shadow) sees the same holes.
#pragma once
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <vector>
#include <embree3/rtcore.h>
#include <glm/glm.hpp>
#include "scene/camera.h"
#include "scene/scene.h"

namespace pxf {

struct Hit {
  unsigned mesh = RTC_INVALID_GEOMETRY_ID;
  unsigned prim = 0;
  float u = 0, v = 0;  // barycentrics of vertices 1 and 2
  float t = 0;
  bool valid() const { return mesh != RTC_INVALID_GEOMETRY_ID; }
};

// A shadow ray: does anything block (0, tmax] along a unit direction from an offset origin?
struct ShadowRay {
  glm::vec3 origin{0.0f};
  glm::vec3 direction{0.0f};
  float tmax = 0.0f;
};

// How a batch of rays is laid out, for Embree's stream traversal: camera rays of one tile are
// coherent (packet traversal pays off); bounce and shadow rays are not.
enum class RayCoherence { Coherent, Incoherent };

// The stream queries hand Embree at most this many rays a call (stack buffers; streams of 64
// traced as fast as 256).
constexpr size_t kEmbreeStreamChunk = 64;

class RayRecorder;  // pathtracer/ray_recorder.h

struct SurfacePoint {
  glm::vec3 position{0.0f};
  glm::vec3 geometric_normal{0.0f};  // unit, the triangle's winding orientation
  glm::vec3 vertex_normal{0.0f};     // interpolated vertex normal, unit, no normal map
  glm::vec3 shading_normal{0.0f};    // vertex normal with the normal map applied
  glm::vec3 clearcoat_normal{0.0f};  // vertex normal with the clearcoat's normal map applied
  glm::vec2 uv0{0.0f}, uv1{0.0f};
  // The width in uv0 units of the ray's footprint here (surface_point's cone_width): which mip
  // level the material's look-ups read (normal maps excepted). 0: level 0.
  float texture_footprint = 0.0f;
  glm::vec4 color{1.0f};             // COLOR_0
  const Material* material = nullptr;
  bool front_face = true;            // the ray arrived on the side the geometric normal faces
};

class EmbreeScene {
 public:
  explicit EmbreeScene(const Scene& scene);
  ~EmbreeScene();
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;

  // Closest hit in (0, tmax]. The ray's origin must already be offset off the surface it leaves.
  Hit intersect(const Ray& ray, float tmax = std::numeric_limits<float>::infinity()) const;
  bool occluded(glm::vec3 origin, glm::vec3 direction, float tmax) const;
  // The same queries for `count` rays at once, as Embree ray streams (rtcIntersect1M,
  // rtcOccluded1M): per ray the same answer as the single-ray calls (bit for bit, measured on the
  // built-in scenes), at a lower cost per ray. hits[i] / occluded[i] belong to rays[i].
  void intersect(const Ray* rays, size_t count, RayCoherence coherence, Hit* hits) const;
  void occluded(const ShadowRay* rays, size_t count, bool* occluded) const;
  // cone_width: the world-space width of the ray's footprint at the hit (0: textures at level 0).
  SurfacePoint surface_point(const Hit& hit, const Ray& ray, float cone_width = 0.0f) const;

  const Scene& scene() const { return scene_; }
  RTCScene handle() const { return rtc_scene_; }
  float triangle_area(unsigned mesh, unsigned prim) const;
  glm::vec3 face_normal(unsigned mesh, unsigned prim) const { return face_normals_[mesh][prim]; }

  // Ray recording (pathtracer/ray_recorder.h, the throughput bench): while set, the four queries
  // above log every ray they hand to Embree, with its answer; nullptr (the default) records
  // nothing, at the cost of one branch per query. Set it only while no thread traces.
  void set_ray_recorder(RayRecorder* recorder) { recorder_ = recorder; }

  // Alpha data handed to Embree's filter functions (one per mesh with a MASK or BLEND material).
  struct MaskData {
    const Scene* scene;
    const Mesh* mesh;
    const Material* material;
  };

 private:
  void map_normal(const TextureRef& map, float scale, glm::vec4 tangent, const SurfacePoint& sp, glm::vec3* normal) const;

  const Scene& scene_;
  RTCDevice device_ = nullptr;
  RTCScene rtc_scene_ = nullptr;
  std::vector<std::vector<glm::vec3>> face_normals_;  // per mesh, per triangle, unit
  std::vector<MaskData> mask_data_;
  RayRecorder* recorder_ = nullptr;  // set_ray_recorder
};

// What EmbreeScene hands Embree, and what `pxf bench pathtracer` replays: the ray of a query from
// `origin` (hits in [tnear, tmax]), the same for a closest-hit query with no hit yet, and the
// query's context, flagged coherent or incoherent.
RTCRay embree_ray(glm::vec3 origin, glm::vec3 direction, float tmax, float tnear);
RTCRayHit embree_ray_hit(glm::vec3 origin, glm::vec3 direction, float tmax, float tnear);
RTCIntersectContext intersect_context(RayCoherence coherence);
// How the queries read Embree's answer: a closest hit (invalid on a miss), and occlusion.
Hit hit_of(const RTCRayHit& rh);
bool is_occluded(const RTCRay& r);

// Moves a point off a surface to the side `direction` leaves to, scaled to the point's magnitude
// so far-away geometry does not self-intersect. Inline: every bounce and shadow ray calls it.
inline glm::vec3 offset_ray_origin(glm::vec3 position, glm::vec3 geometric_normal, glm::vec3 direction) {
  float scale = std::max(std::max(std::abs(position.x), std::abs(position.y)), std::abs(position.z));
  float eps = 1e-4f * (1.0f + scale);
  return position + (glm::dot(direction, geometric_normal) >= 0.0f ? eps : -eps) * geometric_normal;
}

// A shadow ray between two surface points (pbrt's SpawnRayTo): both ends are moved off their
// surfaces towards each other, and the direction and distance are those between the moved ends.
// Aiming from an offset origin at the un-offset target instead ends the ray just beyond the
// target's plane; at grazing angles it then crosses that plane before tmax, and an emitter near
// the shading point shadows itself. to_normal = 0 for a target on no surface (a point light).
inline ShadowRay shadow_ray_between(glm::vec3 from, glm::vec3 from_normal, glm::vec3 to, glm::vec3 to_normal) {
  const glm::vec3 d = to - from;
  const glm::vec3 origin = offset_ray_origin(from, from_normal, d);
  const glm::vec3 target = offset_ray_origin(to, to_normal, -d);
  const glm::vec3 span = target - origin;
  const float distance = glm::length(span);
  if (!(distance > 0.0f)) return ShadowRay{origin, glm::vec3(0.0f), 0.0f};  // nothing to test
  constexpr float kShadowEpsilon = 1e-4f;  // stop short of the target by this fraction
  return ShadowRay{origin, span / distance, distance * (1.0f - kShadowEpsilon)};
}

}  // namespace pxf
