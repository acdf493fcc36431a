#pragma once

// Light through a specular sphere, sampled by solving for its path (docs/sampling.md, "Caustics
// solved through spheres"): a point on the emissive triangles, then a direction from the shading
// point whose path through the sphere (a mirror's reflection, or glass's two refractions) reaches
// that point. The solution is exact for the analytic sphere through the mesh's vertices; the path
// itself is then traced through the mesh, so where the two differ the strategy only loses
// efficiency: its pdf is the density of the directions it draws, whatever they reach.

#include <cstddef>
#include <vector>

#include <glm/glm.hpp>

#include "pathtracer/sampling.h"

namespace pxf {

// A perfectly specular mesh whose vertices lie on one sphere.
struct SphereCaster {
  glm::dvec3 center{0.0};
  double radius = 0.0;
  bool mirror = false;  // reflects; otherwise glass of index `ior`, entered and left by refraction
  double ior = 1.5;
};

// The caster of a mesh whose vertices all lie within kSphereFitTolerance x radius of one sphere
// about their bounding box's centre, with their normals radial (within that tolerance of the
// cosine); false for any other mesh, and for one without vertex normals.
constexpr double kSphereFitTolerance = 1e-3;
bool fit_sphere_caster(const std::vector<glm::vec3>& positions, const std::vector<glm::vec3>& normals,
                       SphereCaster* out);

// The analytic path from x along the unit direction w: the ray that leaves the sphere (its origin
// on the sphere, its unit direction). False when the ray misses the sphere, x is inside it, or
// the light is totally reflected.
bool trace_sphere_caster(const SphereCaster& caster, const glm::dvec3& x, const glm::dvec3& w, glm::dvec3* origin,
                         glm::dvec3* direction);

// The directions from x whose analytic path passes through y, at most kMaxSphereCasterPaths, in
// a fixed order. A path stays in the plane of x, the centre and y, so they are the roots of a
// function of one variable (the ray's signed distance from the centre), bracketed by a scan of
// kGlassScan steps (kMirrorScan for a mirror, whose one reflection bends the function less)
// even in the entry angle and refined by the Illinois method; two roots within one step are
// missed, which the pdf accounts for (it counts only the paths this function finds). None when
// x, the centre and y are on one line, or x or y is inside the sphere.
// Paths that meet the sphere farther than kSphereCasterRim x radius from its centre's line are
// left to the other strategies: toward the silhouette the map from directions to the light bends
// without bound, and its pdf with it.
constexpr double kSphereCasterRim = 0.95;
constexpr int kMaxSphereCasterPaths = 8;
constexpr int kGlassScan = 96, kMirrorScan = 24;
int solve_sphere_caster(const SphereCaster& caster, const glm::dvec3& x, const glm::dvec3& y, glm::dvec3* directions);

class SphereCausticSampler {
 public:
  struct Emitter {
    glm::dvec3 p0{0.0}, e1{0.0}, e2{0.0};
    double area = 0.0;
  };
  SphereCausticSampler() = default;
  // `powers`: each emitter's selection weight (its power).
  SphereCausticSampler(std::vector<Emitter> emitters, const std::vector<float>& powers);
  bool empty() const { return emitters_.empty(); }

  // A direction from x toward the emitters through the caster: emitter by power (u_select), a
  // point uniform on it (u_point), one of the paths to it chosen uniformly (u_select rescaled).
  // False when there is none; *pdf: the direction's density, pdf(w), without solving again for
  // the point it was drawn for.
  bool sample(const SphereCaster& caster, glm::vec3 x, float u_select, glm::vec2 u_point, glm::vec3* w,
              float* pdf) const;
  // The solid-angle density with which sample() draws w: over every emitter point y the analytic
  // path along w crosses, p(y) |dA_y / d omega| / (the number of paths solve finds to y), where
  // solve finds w itself among them.
  float pdf(const SphereCaster& caster, glm::vec3 x, glm::vec3 w) const;

 private:
  // pdf(), with emitter `known` (>= 0) crossed at a point whose paths are known: `known_count` of them.
  float density(const SphereCaster& caster, const glm::dvec3& x, const glm::dvec3& w, int known, int known_count) const;
  std::vector<Emitter> emitters_;
  Distribution1D choice_;
};

}  // namespace pxf
