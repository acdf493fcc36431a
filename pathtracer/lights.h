// Light sampling for next event estimation: emissive triangles (power-weighted near-field choice;
// area sampling, or solid-angle sampling of a quad near the shading point), the environment
// (luminance x sin(theta) importance sampling on the equirect image) and KHR punctual lights
// (delta lights, NEE only). One light sample per call: a category
// (triangles / environment / punctual) is picked first, in proportion to its estimated power.
// Punctual lights, when there are at most kMaxFixedLights, are not in that choice: every vertex
// samples each of them besides (fixed_light_sample), one shadow ray each and no random number
// (docs/sampling.md).
#pragma once
#include <limits>
#include <vector>
#include <glm/glm.hpp>
#include "pathtracer/environment_visibility.h"
#include "pathtracer/sampling.h"
#include "scene/scene.h"

namespace pxf {

struct LightSample {
  glm::vec3 wi{0.0f};        // unit direction from the shading point to the light
  float distance = 0.0f;     // to the sampled point; infinity for environment / directional
  glm::vec3 radiance{0.0f};  // emitted radiance towards the shading point (delta: intensity / d^2)
  float pdf = 0.0f;          // solid-angle pdf incl. selection (delta: selection probability)
  bool delta = false;
  glm::vec3 point{0.0f}, normal{0.0f};  // the sampled point (finite distance); normal 0 off surfaces
};

// A light path's start (path guiding's training light, docs/guiding.md): it leaves `origin` along
// `direction` carrying `flux` (the power it stands for: the lights' total over the number drawn).
struct EmittedPhoton {
  glm::vec3 origin{0.0f}, direction{0.0f}, flux{0.0f};
  bool from_infinity = false;  // an environment's or a sun's: its wavefront is plane, not from `origin`
};

class LightSampler {
 public:
  explicit LightSampler(const Scene& scene);

  bool empty() const { return category_count_ == 0 && fixed_.empty(); }  // nothing emits: the image is black
  bool has_environment() const { return env_ != nullptr; }

  // `sky`: what the point's region learned of the environment's visible part (light through
  // openings, environment_visibility.h); an environment sample then comes from the mixture of it
  // and the environment's own distribution, with the mixture's pdf.
  bool sample(glm::vec3 position, float u_select, glm::vec2 u, LightSample* out, const VisibleSky* sky = nullptr) const;
  // The same distribution from one 2D number: u.x picks the light and, rescaled to the chosen
  // light's share of [0,1), is reused as the first coordinate of the point on it. A stratified
  // (low-discrepancy) u then stays stratified on every light, which a separate selection number
  // does not give.
  bool sample(glm::vec3 position, glm::vec2 u, LightSample* out, const VisibleSky* sky = nullptr) const;

  // A photon from all the lights' emission, each light chosen in proportion to its power (suns
  // and the environment enter through a disc facing them that covers the scene). Emissive
  // textures count at their material's factor: the photons only train a guide, so an
  // approximate emission costs variance, never bias. False when nothing emits.
  bool sample_emission(glm::vec2 u_select, glm::vec2 u_position, glm::vec2 u_direction, EmittedPhoton* out) const;

  // Solid-angle pdf (incl. selection) with which sample() would pick this point of an emissive
  // triangle seen from `from`; 0 for triangles that are not lights.
  float pdf_triangle(unsigned mesh, unsigned prim, glm::vec3 from, glm::vec3 point, glm::vec3 face_normal) const;
  // Incl. selection; `sky`: the point's learned sky, as sample() was given it.
  float pdf_environment(glm::vec3 direction, const VisibleSky* sky = nullptr) const;
  glm::vec3 environment_radiance(glm::vec3 direction) const;  // 0 without an environment
  // Both for a ray that escaped: the radiance, and pdf_environment() into *pdf (one map lookup).
  glm::vec3 environment_hit(glm::vec3 direction, const VisibleSky* sky, float* pdf) const;

  // Parts exposed for the statistical tests.
  size_t emissive_triangle_count() const { return triangles_.size(); }
  // The probability of picking emissive triangle `light` among the triangles, seen from `from`
  // (near-field selection, below); without near-field selection it is its share of the power.
  float triangle_selection_pmf(size_t light, glm::vec3 from) const;
  // Its share of the emissive triangles' power (the selection without near-field selection).
  float triangle_power_pmf(size_t light) const { return triangle_dist_.pmf(light); }
  // Samples a point on the emissive triangles for a shading point at `from`: returns the light
  // index and the area pdf (incl. the triangle's selection, not the category's).
  size_t sample_triangle_point(glm::vec3 from, float u_select, glm::vec2 u, glm::vec3* point, glm::vec2* barycentrics,
                               float* area_pdf) const;
  // As above with u.x both selecting the triangle and, rescaled, the point's first coordinate.
  size_t sample_triangle_point(glm::vec3 from, glm::vec2 u, glm::vec3* point, glm::vec2* barycentrics,
                               float* area_pdf) const;

  // Near-field selection: with 2 to kMaxNearFieldClusters emissive meshes, the mesh is picked with
  // probability 1/2 (its power share) + 1/2 (its share of power / (d^2 + (r/10)^2)), d the
  // distance from the shading point to the mesh's bounding box and r the box's half diagonal (so
  // a long thin strip counts as near all along it); inside a mesh the triangle goes by power. The
  // power half keeps every light's probability at least half its power share wherever the
  // distance term misjudges (occlusion, the shading normal). A one-sided planar mesh (a panel, an
  // LED strip) gets probability 0 at points behind its plane, where it cannot light them, and the
  // others share its part.
  static constexpr size_t kMaxNearFieldClusters = 16;
  // A rectangular emitter (a quad of two triangles with perpendicular edges) is sampled uniformly
  // in the solid angle it subtends where its diagonal is at least its distance (this factor on
  // the squares), else uniformly in area, where the two pdfs are alike and area sampling is
  // cheaper (docs/sampling.md).
  static constexpr float kSolidAngleNearness = 1.0f;
  // The environment's importance map: at most about this many cells wide where the coarser map
  // multiplies the variance of sampling the map's own luminance by at most the factor below,
  // else one cell per texel (environment_importance in lights.cpp; docs/sampling.md).
  static constexpr int kEnvironmentImportanceWidth = 256;
  static constexpr double kEnvironmentCoarseVarianceFactor = 1.1;
  bool near_field_selection() const { return !clusters_.empty(); }
  // pdf without selection; `uv`: the direction's place on the equirect map.
  glm::vec3 sample_environment_direction(glm::vec2 u, float* pdf, glm::vec2* uv = nullptr) const;
  float environment_direction_pdf(glm::vec3 direction) const;  // pdf without selection

  struct EmissiveTriangle {
    unsigned mesh, prim;
    glm::vec3 p0, e1, e2, normal;
    float area;
    const Material* material;
    bool textured = false;   // its emission varies over it (an emissive texture): needs its uvs
    int parallelogram = -1;  // index into parallelograms_ when this and a neighbour form one
  };
  const EmissiveTriangle& triangle(size_t light) const { return triangles_[light]; }
  // The side a flat one-sided emitter (a panel, an LED strip, a quad) lights: a point behind its
  // plane gets nothing from it, however it is sampled.
  struct FrontSide {
    bool one_sided = false;  // false: lights both sides (double-sided, or not flat)
    glm::vec3 normal{0.0f}, point{0.0f};
    bool can_light(glm::vec3 from) const { return !one_sided || glm::dot(from - point, normal) > 0.0f; }
  };
  // Two consecutive triangles of one emissive mesh that form a parallelogram (a quad split on its
  // diagonal): origin + u edge_u + v edge_v, u + v <= 1 being the first triangle. With the shared
  // selection the point goes on the whole parallelogram, so the 2D strata of u cover the quad as
  // an affine image instead of half of them warped onto each triangle.
  struct Parallelogram {
    size_t first = 0;  // its first triangle; the second is first + 1
    glm::vec3 origin{0.0f}, edge_u{0.0f}, edge_v{0.0f};
    // Indexed by which triangle (0 first, 1 second): its share of the pair's selection probability.
    // A table and index arithmetic, not branches: which triangle a light sample lands in is a coin
    // flip, and a branch on it was mispredicted half the time (docs/sampling.md).
    float share_of[2] = {0.5f, 0.5f};
    float share(size_t triangle) const { return share_of[triangle - first]; }
    // Where the triangle's share starts in the pair's: 0 for the first, the first's share for the second.
    float share_start(size_t triangle) const { return static_cast<float>(triangle - first) * share_of[0]; }
    bool rectangle = false;    // edges perpendicular: solid-angle sampling applies
    FrontSide front;
    float inv_length2_u = 0.0f, inv_length2_v = 0.0f, diagonal2 = 0.0f;
    // The barycentrics of triangle s's corners 1 and 2 (its own order) at the pair's point
    // origin + a edge_u + b edge_v: bary_coef[s][k] . (1, a, b), affine in (a, b) on each triangle.
    float bary_coef[2][2][3] = {{{0, 1, 0}, {0, 0, 1}}, {{0, 1, 0}, {0, 0, 1}}};
  };
  // A rectangle large against its distance (squared diagonal at least kSolidAngleNearness times
  // the squared distance to its centre): there area sampling's density, which follows cos / r^2
  // over the light, varies most; elsewhere it is nearly constant and area sampling is as good.
  // A point behind a one-sided rectangle gets nothing from it whichever way it is sampled.
  static bool near_enough_for_solid_angle(const Parallelogram& q, glm::vec3 from) {
    if (!q.front.can_light(from)) return false;
    const glm::vec3 to_center = q.origin + 0.5f * (q.edge_u + q.edge_v) - from;
    return q.diagonal2 >= kSolidAngleNearness * glm::dot(to_center, to_center);
  }
  const Parallelogram& parallelogram(size_t index) const { return parallelograms_[index]; }

  // Punctual lights (suns, points, spots) sampled at every vertex, outside the category choice: with
  // up to this many a light costs one shadow ray and no random number, and its light at a vertex is
  // exact, free of noise (so the path tracer keeps the first vertex's in LV: docs/method.md 1.1).
  // With more, they all keep their place in the punctual category.
  static constexpr size_t kMaxFixedLights = 4;
  size_t fixed_light_count() const { return fixed_.size(); }
  // Fixed light `index`'s sample at `position`: direction, radiance, pdf 1 (always taken), delta.
  // False where it cannot light the point (a point light at it, a spot's cone, its range).
  bool fixed_light_sample(size_t index, glm::vec3 position, LightSample* out) const;

  // Category selection probabilities and the power estimates they come from.
  float triangles_probability() const { return p_triangles_; }
  float environment_probability() const { return p_environment_; }
  float punctual_probability() const { return p_punctual_; }
  static double triangle_power(double weighted_area_sum);  // sum of L x area x sides
  // The estimates summed over every light, the fixed ones included, and the environment's alone.
  double estimated_power() const { return power_triangles_ + power_environment_ + power_punctual_ + power_fixed_; }
  double estimated_environment_power() const { return power_environment_; }
  static double environment_power(const Environment& env, float scene_radius);
  static double punctual_power(const PunctualLight& light, float scene_radius);

 private:
  // Both sample() overloads: with reuse_select, u.x is replaced by u_select rescaled within the
  // chosen category and light.
  bool sample_light(glm::vec3 position, float u_select, glm::vec2 u, bool reuse_select, const VisibleSky* sky,
                    LightSample* out) const;
  size_t triangle_point(glm::vec3 from, float u_select, glm::vec2 u, bool reuse_select, glm::vec3* point,
                        glm::vec2* barycentrics, float* area_pdf) const;
  // Picks an emissive triangle for a shading point at `from`; u_remapped (may be null): u_select
  // rescaled within the choice. pmf: the triangle's selection probability among the triangles.
  size_t pick_triangle(glm::vec3 from, float u_select, float* u_remapped, float* pmf) const;
  void build_near_field_clusters(const std::vector<float>& powers);
  FrontSide front_side(size_t first, size_t end) const;  // of triangles [first, end)
  // p(cluster | from) of every cluster into `out` (kMaxNearFieldClusters entries).
  void cluster_probabilities(glm::vec3 from, float* out) const;
  bool triangle_sample(glm::vec3 position, size_t light, glm::vec3 point, glm::vec2 barycentrics, float area_pdf,
                       LightSample* out) const;
  bool sample_environment(glm::vec2 u, const VisibleSky* sky, LightSample* out) const;
  float environment_density(glm::vec2 uv, glm::vec3 direction) const;  // at the direction's uv
  float pdf_environment_at(glm::vec2 uv, glm::vec3 direction, const VisibleSky* sky) const;
  bool sample_punctual(glm::vec3 position, float u_select, LightSample* out) const;
  static bool punctual_sample(const PunctualLight& light, glm::vec3 position, float pdf, LightSample* out);

  // Whether points of rectangle q seen from `from` are drawn uniformly in solid angle (a rectangle
  // that is large against its distance and not seen edge-on) rather than uniformly in area; sr is
  // then set up. Sampling and pdf_triangle() ask the same question, so they agree.
  bool solid_angle_sampling(const Parallelogram& q, glm::vec3 from, SphericalRectangle* sr) const {
    return q.rectangle && near_enough_for_solid_angle(q, from) && sr->init(from, q.origin, q.edge_u, q.edge_v);
  }
  // The triangle of pair q holding its point origin + uv.x edge_u + uv.y edge_v, and its barycentrics there.
  size_t pair_triangle(const Parallelogram& q, glm::vec2 uv, glm::vec2* barycentrics) const;
  void find_parallelograms(size_t first, size_t end);

  bool emit_from_triangle(glm::vec2 u_select, glm::vec2 u_position, glm::vec2 u_direction, EmittedPhoton* out) const;
  // A photon of a light at infinity reaching the scene from `toward_light`, with that radiance
  // (environment) or irradiance (sun) over the given solid-angle density (1 for a sun).
  EmittedPhoton emit_from_infinity(glm::vec3 toward_light, glm::vec3 radiance, float pdf, glm::vec2 u_position) const;

  const Scene& scene_;
  std::vector<EmissiveTriangle> triangles_;
  std::vector<Parallelogram> parallelograms_;
  std::vector<int> mesh_light_offset_;  // first light index of each mesh's triangles, -1: not emissive
  Distribution1D triangle_dist_;
  struct Cluster {  // one emissive mesh for near-field selection
    size_t first = 0;          // its first triangle in triangles_ (its triangles are contiguous)
    Distribution1D triangles;  // by power inside the mesh
    double power_share = 0.0;  // of all triangles' power
    float power = 0.0f;        // the sum of its triangle weights
    glm::vec3 lo{0.0f}, hi{0.0f};  // bounding box
    float floor2 = 0.0f;           // (half diagonal / 10)^2, added to the squared distance
    // Behind a one-sided flat mesh its probability is 0 (its light is exactly 0 there).
    FrontSide front;
  };
  std::vector<Cluster> clusters_;          // empty: selection by power alone
  std::vector<int> triangle_cluster_;      // per triangle, with clusters_
  const Environment* env_ = nullptr;
  Distribution2D env_dist_;
  std::vector<const PunctualLight*> punctual_;
  std::vector<const PunctualLight*> fixed_;  // sampled at every vertex (kMaxFixedLights)
  // Category selection: [0, p_tri) triangles, [p_tri, p_tri + p_env) environment, rest punctual.
  float p_triangles_ = 0.0f, p_environment_ = 0.0f, p_punctual_ = 0.0f;
  // sample_emission's choice by power: [triangles, environment, each of punctual_, each of fixed_].
  Distribution1D emission_dist_;
  glm::vec3 scene_center_{0.0f};
  float scene_radius_ = 1.0f;
  double power_triangles_ = 0.0, power_environment_ = 0.0, power_punctual_ = 0.0, power_fixed_ = 0.0;
  int category_count_ = 0;
};

}  // namespace pxf
