// Light sampling for next event estimation: emissive triangles (area sampling, power-weighted
// triangle choice), the environment (luminance x sin(theta) importance sampling on the equirect
// image) and KHR punctual lights (delta lights, NEE only). One light sample per call: a category
// (triangles / environment / punctual) is picked first, in proportion to its estimated power.
#pragma once
#include <limits>
#include <vector>
#include <glm/glm.hpp>
#include "pathtracer/sampling.h"
#include "pathtracer/scene.h"

namespace pxf {

struct LightSample {
  glm::vec3 wi{0.0f};        // unit direction from the shading point to the light
  float distance = 0.0f;     // to the sampled point; infinity for environment / directional
  glm::vec3 radiance{0.0f};  // emitted radiance towards the shading point (delta: intensity / d^2)
  float pdf = 0.0f;          // solid-angle pdf incl. selection (delta: selection probability)
  bool delta = false;
  glm::vec3 point{0.0f}, normal{0.0f};  // the sampled point (finite distance); normal 0 off surfaces
};

// Direction <-> equirect coordinates (scene.h convention).
glm::vec2 equirect_uv(glm::vec3 direction);
glm::vec3 equirect_direction(glm::vec2 uv);

class LightSampler {
 public:
  explicit LightSampler(const Scene& scene);

  bool empty() const { return category_count_ == 0; }  // nothing emits: the image is black
  bool has_environment() const { return env_ != nullptr; }

  bool sample(glm::vec3 position, float u_select, glm::vec2 u, LightSample* out) const;
  // The same distribution from one 2D number: u.x picks the light and, rescaled to the chosen
  // light's share of [0,1), is reused as the first coordinate of the point on it. A stratified
  // (low-discrepancy) u then stays stratified on every light, which a separate selection number
  // does not give.
  bool sample(glm::vec3 position, glm::vec2 u, LightSample* out) const;

  // Solid-angle pdf (incl. selection) with which sample() would pick this point of an emissive
  // triangle seen from `from`; 0 for triangles that are not lights.
  float pdf_triangle(unsigned mesh, unsigned prim, glm::vec3 from, glm::vec3 point, glm::vec3 face_normal) const;
  float pdf_environment(glm::vec3 direction) const;   // incl. selection
  glm::vec3 environment_radiance(glm::vec3 direction) const;  // 0 without an environment

  // Parts exposed for the statistical tests.
  size_t emissive_triangle_count() const { return triangles_.size(); }
  float triangle_selection_pmf(size_t light) const { return triangle_dist_.pmf(light); }
  // Samples a point on the emissive triangles: returns the light index and the area pdf.
  size_t sample_triangle_point(float u_select, glm::vec2 u, glm::vec3* point, glm::vec2* barycentrics, float* area_pdf) const;
  // As above with u.x both selecting the triangle and, rescaled, the point's first coordinate.
  size_t sample_triangle_point(glm::vec2 u, glm::vec3* point, glm::vec2* barycentrics, float* area_pdf) const;
  glm::vec3 sample_environment_direction(glm::vec2 u, float* pdf) const;  // pdf without selection
  float environment_direction_pdf(glm::vec3 direction) const;             // pdf without selection

  struct EmissiveTriangle {
    unsigned mesh, prim;
    glm::vec3 p0, e1, e2, normal;
    float area;
    const Material* material;
  };
  const EmissiveTriangle& triangle(size_t light) const { return triangles_[light]; }

  // Category selection probabilities and the power estimates they come from.
  float triangles_probability() const { return p_triangles_; }
  float environment_probability() const { return p_environment_; }
  float punctual_probability() const { return p_punctual_; }
  static double triangle_power(double weighted_area_sum);  // sum of L x area x sides
  static double environment_power(const Environment& env, float scene_radius);
  static double punctual_power(const PunctualLight& light, float scene_radius);

 private:
  bool sample_triangles(glm::vec3 position, float u_select, glm::vec2 u, LightSample* out) const;
  void point_on_triangle(size_t light, float pmf, glm::vec2 u, glm::vec3* point, glm::vec2* barycentrics,
                         float* area_pdf) const;
  bool triangle_sample(glm::vec3 position, size_t light, glm::vec3 point, glm::vec2 barycentrics, float area_pdf,
                       LightSample* out) const;
  bool sample_environment(glm::vec3 position, glm::vec2 u, LightSample* out) const;
  bool sample_punctual(glm::vec3 position, float u_select, LightSample* out) const;

  const Scene& scene_;
  std::vector<EmissiveTriangle> triangles_;
  std::vector<int> mesh_light_offset_;  // first light index of each mesh's triangles, -1: not emissive
  Distribution1D triangle_dist_;
  const Environment* env_ = nullptr;
  Distribution2D env_dist_;
  std::vector<const PunctualLight*> punctual_;
  // Category selection: [0, p_tri) triangles, [p_tri, p_tri + p_env) environment, rest punctual.
  float p_triangles_ = 0.0f, p_environment_ = 0.0f, p_punctual_ = 0.0f;
  double power_triangles_ = 0.0, power_environment_ = 0.0, power_punctual_ = 0.0;
  int category_count_ = 0;
};

}  // namespace pxf
