// Light through chains of perfectly specular surfaces (D S+ L: a caustic), which next event
// estimation cannot reach: from a diffuse vertex, a direction toward one mirror or glass object,
// followed through its delta bounces to the light it reaches, and combined with the vertex's
// BSDF-side strategy by the power heuristic (docs/sampling.md#fireflies). The integrator asks it
// as pbrt-v4's Li asks SampleLd: plan() says whether and toward what a vertex traces a chain,
// light() traces it, and pdf() is the density the BSDF-sampled direction gets in the MIS weight of
// the light it finds through a specular chain.
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "pathtracer/bsdf.h"
#include "pathtracer/caustics/sphere_caustics.h"
#include "pathtracer/embree_scene.h"
#include "pathtracer/lights.h"
#include "pathtracer/pathtracer.h"
#include "pathtracer/sampler.h"

namespace pxf {

class BsdfMaterials;
struct GuidingMixture;

// A sphere subtends solid angle 2 pi (1 - cos a) from a point at distance d from its center, with
// sin a = r / d. Near: at least pi sr (a >= 60 degrees), i.e. d^2 <= r^2 / sin^2 a = r^2 / (1 - cos^2 a).
constexpr float kNearSpecularSolidAngle = 3.14159265358979323846f;
constexpr float kNearSpecularCosHalfAngle = 1.0f - kNearSpecularSolidAngle / (2.0f * 3.14159265358979323846f);
constexpr float kNearSpecularDistance2PerRadius2 = 1.0f / (1.0f - kNearSpecularCosHalfAngle * kNearSpecularCosHalfAngle);
// ... and only toward a mesh whose area is at least this share of its bounding sphere's (on average
// it then covers at least this share of the cone the chain samples).
constexpr double kNearSpecularMinFill = 0.5;

class SpecularChainSampler {
 public:
  // A perfectly specular mesh, seen through its bounding sphere.
  struct Target {
    glm::vec3 center{0.0f};
    float radius = 0.0f;
    float near_distance2 = 0.0f;  // squared distance from the center within which p is near
    int caster = -1;               // index into casters_ when the mesh is a sphere: its light is solved for
    bool mirror_caster = false;    // a mirror sphere: its chains go from every diffuse vertex (Plan)
    bool near(glm::vec3 p) const;  // outside the sphere, and it subtends >= kNearSpecularSolidAngle
  };
  // Which targets a vertex's chain aims at (one of them, chosen uniformly) and the probability
  // that it is traced at all: every target with TraceParams::specular_sampling; else, with
  // TraceParams::specular_chains, the near ones at the first non-delta vertex, and elsewhere
  // (deeper vertices too) the mirror spheres with kFarCasterChainProbability: their solved chains
  // find a mirror's caustic anywhere, also where the camera sees it after a diffuse bounce (the
  // ceiling under cornell's mirror ball).
  struct Plan {
    enum class Targets { All, Near, Casters } targets = Targets::All;
    int candidates = 0;  // 0: no chain
    float probability = 1.0f;
    bool traces() const { return candidates > 0; }
    bool includes(const Target& t, glm::vec3 p) const;
  };
  // A direction a chain starts along, and its solid-angle density under the plan.
  struct Direction {
    glm::vec3 wi{0.0f};
    float pdf = 0.0f;
  };

  // The targets of the scene's perfectly specular meshes; the solved chains toward its spheres
  // draw points on `lights`' emissive triangles.
  SpecularChainSampler(const EmbreeScene& geometry, const LightSampler& lights, const BsdfMaterials& materials);

  bool has_perfect_specular() const { return has_perfect_specular_; }
  // No target: no vertex traces a chain, and plan() need not be asked.
  bool empty() const { return targets_.empty(); }
  // Whether plan() can give any vertex a chain under these params: with the chains of
  // TraceParams::specular_chains only, a scene needs a target that fills its bounding sphere (near
  // chains) or a mirror sphere whose light is solved for (far chains). False: plan() need not be
  // asked, its answer would be no chain everywhere.
  bool traces_any(const TraceParams& params) const {
    return params.specular_sampling ? !targets_.empty() : params.specular_chains && (has_near_targets_ || far_chains());
  }
  const std::vector<Target>& targets() const { return targets_; }

  // The chains a non-delta vertex at p traces (the first one of its path: `first_vertex`).
  Plan plan(glm::vec3 p, const TraceParams& params, bool first_vertex) const;
  // The solid-angle density with which sample() draws wi from p under the plan (0 where it never does).
  float pdf(glm::vec3 p, glm::vec3 wi, const Plan& plan) const { return pdf(p, wi, plan, nullptr, 0.0f); }
  // A direction from p: traced with the plan's probability (u_select below it), toward one of its
  // targets chosen uniformly, in the target's cone or, for a sphere, solved toward a point on the
  // emitters. False: no chain this time.
  bool sample(glm::vec3 p, const Plan& plan, float u_select, glm::vec2 u, Direction* out) const;

  // The light one sampled direction from the vertex at sp reaches through a specular chain, times
  // `throughput` and already MIS-weighted against `mixture`, the pdf of the vertex's BSDF-side
  // strategy. The chain's vertices follow the vertex's index `vertex`, up to max_vertices; rays
  // counts the rays traced, *through_glass is set when the chain refracted.
  glm::vec3 light(const SurfacePoint& sp, const Bsdf& bsdf, const GuidingMixture& mixture, glm::vec3 throughput,
                  int vertex, const Plan& plan, PathSampler& sampler, int max_vertices, uint32_t* rays,
                  bool* through_glass) const;

 private:
  // `drawn_from`, `drawn_pdf`: the target a solved chain drew wi for and that draw's density
  // (SphereCausticSampler::sample's), which need not be solved for again.
  float pdf(glm::vec3 p, glm::vec3 wi, const Plan& plan, const Target* drawn_from, float drawn_pdf) const;
  void set_up_solved_chains();
  // The far chains toward the mirror spheres (Plan::Targets::Casters).
  bool far_chains() const { return solved_chain_share_ > 0.0f && mirror_caster_targets_ > 0; }

  // The chains toward a sphere target are drawn toward the emissive triangles by solving for the
  // path through the sphere (pathtracer/caustics/sphere_caustics.h, docs/sampling.md): all of
  // them, or kSolvedChainShareWithEnvironment where an environment needs the cone's chains too.
  static constexpr size_t kMaxSolvedChainEmitters = 64;  // the pdf visits every emitter
  static constexpr float kSolvedChainShareWithEnvironment = 0.5f;
  // A mirror's image of the light seen from afar is small and its solved density large, so few
  // chains serve it: 1 in 20 diffuse vertices is even at equal time with 1 in 50, and keeps more
  // margin for a mirror that looks larger (docs/sampling.md).
  static constexpr float kFarCasterChainProbability = 0.05f;

  const EmbreeScene& geometry_;
  const LightSampler& lights_;
  const BsdfMaterials& materials_;
  std::vector<Target> targets_;
  int mirror_caster_targets_ = 0;
  std::vector<SphereCaster> casters_;
  SphereCausticSampler caustics_;
  float solved_chain_share_ = 0.0f;
  bool has_perfect_specular_ = false;
  bool has_near_targets_ = false;  // a target that fills its bounding sphere enough for near chains
};

}  // namespace pxf
