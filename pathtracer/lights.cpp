#include "pathtracer/lights.h"

#include <algorithm>
#include <cmath>

#include "pathtracer/bsdf.h"
#include "pathtracer/pathtracer.h"
#include "scene/texture.h"

namespace pxf {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

float emission_power_weight(const Material& m) { return std::max(0.0f, luminance(m.emissive)); }

// glTF's recommended smooth range window (KHR_lights_punctual).
float range_window(float distance, float range) {
  if (range <= 0.0f) return 1.0f;
  float r = distance / range;
  float w = std::min(std::max(1.0f - r * r * r * r, 0.0f), 1.0f);
  return w * w;
}

// glTF's smooth spot cone falloff between the outer and inner cone angles.
float spot_attenuation(const PunctualLight& light, glm::vec3 to_point) {
  float cos_outer = std::cos(light.outer_cone), cos_inner = std::cos(light.inner_cone);
  float scale = 1.0f / std::max(1e-3f, cos_inner - cos_outer);
  float offset = -cos_outer * scale;
  float cd = glm::dot(glm::normalize(light.direction), to_point);
  float a = std::min(std::max(cd * scale + offset, 0.0f), 1.0f);
  return a * a;
}

// The radius of a sphere around the scene's geometry (1 without geometry): environment and
// directional lights deliver their power through its cross-section.
// A sphere around the scene's geometry (radius 1 without geometry): environment and directional
// lights deliver their power through its cross-section.
void scene_bounding_sphere(const Scene& scene, glm::vec3* center, float* radius) {
  glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
  for (const Mesh& mesh : scene.meshes)
    for (const glm::vec3& p : mesh.positions)
      if (is_finite(p)) lo = glm::min(lo, p), hi = glm::max(hi, p);
  *center = glm::vec3(0.0f);
  *radius = 1.0f;
  if (!(hi.x >= lo.x)) return;
  *center = 0.5f * (lo + hi);
  const float r = 0.5f * glm::length(hi - lo);
  if (r > 0.0f && std::isfinite(r)) *radius = r;
}

}  // namespace

// Luminous powers, in the units of radiance x area x solid angle, used to share light samples
// between the light types. Lambertian emitters: pi x L x area per emitting side (the triangle
// weights already hold L x area x sides).
double LightSampler::triangle_power(double weighted_area_sum) { return kPi * weighted_area_sum; }

// An environment sends pi r^2 x integral of L over the sphere through a scene of radius r (the
// irradiance from each direction times the scene's cross-section).
double LightSampler::environment_power(const Environment& env, float scene_radius) {
  const Texture& image = env.image;
  double integral = 0;
  for (int y = 0; y < image.height; ++y) {
    const double sin_theta = std::sin(kPi * (y + 0.5) / image.height);
    for (int x = 0; x < image.width; ++x) {
      const glm::vec4& t = image.texels[static_cast<size_t>(y) * image.width + x];
      const double l = luminance(glm::vec3(t));
      if (std::isfinite(l) && l > 0.0) integral += l * sin_theta;
    }
  }
  integral *= (2.0 * kPi / image.width) * (kPi / image.height) * env.strength;
  return kPi * scene_radius * scene_radius * integral;
}

// Point: 4 pi I; spot: 2 pi (1 - cos of the mean cone angle) I; directional: E x pi r^2.
double LightSampler::punctual_power(const PunctualLight& light, float scene_radius) {
  const double intensity = luminance(light.color) * light.intensity;
  switch (light.type) {
    case PunctualLight::Type::Point: return 4.0 * kPi * intensity;
    case PunctualLight::Type::Spot:
      return 2.0 * kPi * (1.0 - std::cos(0.5 * (light.inner_cone + light.outer_cone))) * intensity;
    case PunctualLight::Type::Directional: return kPi * scene_radius * scene_radius * intensity;
  }
  return 0.0;
}

namespace {

struct ImportanceMap {
  std::vector<float> weights;
  int width = 0, height = 0;
};

// The environment's importance map: luminance x sin(theta) per texel, or summed over square
// blocks of texels so that the map is about LightSampler::kEnvironmentImportanceWidth cells wide.
// Every environment sample reads a random row of the map, and a full-resolution one (megabytes for
// a 2K map) misses the cache at each read; a coarse one stays in it, and environment-lit scenes
// trace more paths per second. Within a block the coarse map is uniform, so it is kept only where that
// costs little variance: sampling a function proportional to the texel weights w_t with the
// coarse pmf q_t instead of p_t = w_t / W multiplies its variance by sum p_t^2 / q_t (1 when
// every block is uniform), which must stay within kEnvironmentCoarseVarianceFactor. A sun drawn
// into the map (a few bright texels in a block) fails that and keeps the full map. The pdf is
// the sampled map's in either case, so the estimate stays unbiased.
ImportanceMap environment_importance(const Texture& image) {
  ImportanceMap fine{std::vector<float>(static_cast<size_t>(image.width) * image.height), image.width, image.height};
  for (int y = 0; y < image.height; ++y) {
    const float sin_theta = std::sin(kPi * (y + 0.5f) / image.height);
    for (int x = 0; x < image.width; ++x) {
      const size_t i = static_cast<size_t>(y) * image.width + x;
      const float w = luminance(glm::vec3(image.texels[i])) * sin_theta;
      fine.weights[i] = std::isfinite(w) && w > 0.0f ? w : 0.0f;
    }
  }
  const int block = (image.width + LightSampler::kEnvironmentImportanceWidth - 1) / LightSampler::kEnvironmentImportanceWidth;
  if (block <= 1) return fine;
  ImportanceMap coarse{{}, (image.width + block - 1) / block, (image.height + block - 1) / block};
  coarse.weights.assign(static_cast<size_t>(coarse.width) * coarse.height, 0.0f);
  std::vector<double> sums(coarse.weights.size(), 0.0);
  std::vector<int> texels(coarse.weights.size(), 0);
  // The cell holding texel (x, y)'s centre (x / block where the block divides the width).
  const auto cell_of = [&](int x, int y) {
    const size_t cx = (2 * static_cast<size_t>(x) + 1) * coarse.width / (2 * static_cast<size_t>(image.width));
    const size_t cy = (2 * static_cast<size_t>(y) + 1) * coarse.height / (2 * static_cast<size_t>(image.height));
    return cy * coarse.width + cx;
  };
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const size_t c = cell_of(x, y);
      sums[c] += fine.weights[static_cast<size_t>(y) * image.width + x];
      ++texels[c];
    }
  double total = 0.0;
  for (double w : sums) total += w;
  if (!(total > 0.0) || !std::isfinite(total)) return fine;
  double factor = 0.0;  // sum over texels of p_t^2 / q_t, q_t = (W_cell / W) / texels in the cell
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const double w = fine.weights[static_cast<size_t>(y) * image.width + x];
      const size_t c = cell_of(x, y);
      if (w > 0.0) factor += w * w * texels[c] / (total * sums[c]);
    }
  if (!(factor <= LightSampler::kEnvironmentCoarseVarianceFactor)) return fine;
  for (size_t c = 0; c < sums.size(); ++c) coarse.weights[c] = static_cast<float>(sums[c]);
  return coarse;
}

}  // namespace

LightSampler::LightSampler(const Scene& scene) : scene_(scene) {
  std::vector<float> powers;
  mesh_light_offset_.assign(scene.meshes.size(), -1);
  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    const Mesh& mesh = scene.meshes[m];
    const Material& material = scene.materials[mesh.material];
    float weight = emission_power_weight(material);
    if (!(weight > 0.0f) || !std::isfinite(weight)) continue;
    mesh_light_offset_[m] = static_cast<int>(triangles_.size());
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
      const glm::uvec3& tri = mesh.triangles[t];
      EmissiveTriangle e;
      e.mesh = static_cast<unsigned>(m);
      e.prim = static_cast<unsigned>(t);
      e.p0 = mesh.positions[tri.x];
      e.e1 = mesh.positions[tri.y] - e.p0;
      e.e2 = mesh.positions[tri.z] - e.p0;
      glm::vec3 n = glm::cross(e.e1, e.e2);
      float len = glm::length(n);
      e.area = 0.5f * len;
      e.normal = len > 0.0f ? n / len : glm::vec3(0.0f, 0.0f, 1.0f);
      e.material = &material;
      e.textured = material.emissive_texture.valid();
      triangles_.push_back(e);
      powers.push_back(e.area * weight * (material.double_sided ? 2.0f : 1.0f));
    }
    find_parallelograms(static_cast<size_t>(mesh_light_offset_[m]), triangles_.size());
  }
  triangle_dist_ = Distribution1D(powers);
  build_near_field_clusters(powers);

  if (scene.environment && scene.environment->strength > 0.0f && !scene.environment->image.texels.empty()) {
    const ImportanceMap map = environment_importance(scene.environment->image);
    env_dist_ = Distribution2D(map.weights, map.width, map.height);
    if (env_dist_.valid()) env_ = &*scene.environment;
  }
  for (const PunctualLight& light : scene.lights)
    if (light.intensity > 0.0f && std::isfinite(light.intensity) && max_component(light.color) > 0.0f)
      punctual_.push_back(&light);
  if (punctual_.size() <= kMaxFixedLights) fixed_.swap(punctual_);  // more: chosen among themselves, by the category

  bool has_tri = triangle_dist_.valid(), has_env = env_ != nullptr, has_punctual = !punctual_.empty();
  category_count_ = int(has_tri) + int(has_env) + int(has_punctual);
  scene_bounding_sphere(scene, &scene_center_, &scene_radius_);
  const float scene_radius = scene_radius_;
  std::vector<float> emission_powers{has_tri ? static_cast<float>(triangle_power(triangle_dist_.total())) : 0.0f,
                                     has_env ? static_cast<float>(environment_power(*env_, scene_radius)) : 0.0f};
  for (const auto* lights : {&punctual_, &fixed_})
    for (const PunctualLight* light : *lights) emission_powers.push_back(static_cast<float>(punctual_power(*light, scene_radius)));
  for (float& power : emission_powers)
    if (!std::isfinite(power)) power = 0.0f;
  emission_dist_ = Distribution1D(emission_powers);
  if (category_count_ == 0) return;
  power_triangles_ = has_tri ? triangle_power(triangle_dist_.total()) : 0.0;
  power_environment_ = has_env ? environment_power(*env_, scene_radius) : 0.0;
  power_punctual_ = 0.0;
  for (const PunctualLight* light : punctual_) power_punctual_ += punctual_power(*light, scene_radius);
  power_fixed_ = 0.0;
  for (const PunctualLight* light : fixed_) power_fixed_ += punctual_power(*light, scene_radius);
  const double total = power_triangles_ + power_environment_ + power_punctual_;
  if (!(total > 0.0) || !std::isfinite(total)) {  // no usable estimate: equal shares
    float share = 1.0f / category_count_;
    p_triangles_ = has_tri ? share : 0.0f;
    p_environment_ = has_env ? share : 0.0f;
  } else {
    p_triangles_ = static_cast<float>(power_triangles_ / total);
    p_environment_ = static_cast<float>(power_environment_ / total);
  }
  p_punctual_ = has_punctual ? std::max(0.0f, 1.0f - p_triangles_ - p_environment_) : 0.0f;
}

bool LightSampler::sample(glm::vec3 position, float u_select, glm::vec2 u, LightSample* out,
                          const VisibleSky* sky) const {
  return sample_light(position, u_select, u, false, sky, out);
}

bool LightSampler::sample(glm::vec3 position, glm::vec2 u, LightSample* out, const VisibleSky* sky) const {
  return sample_light(position, u.x, u, true, sky, out);
}

bool LightSampler::sample_light(glm::vec3 position, float u_select, glm::vec2 u, bool reuse_select,
                                const VisibleSky* sky, LightSample* out) const {
  if (category_count_ == 0) return false;
  // Remap u_select within the chosen category so it can pick the light inside it.
  if (u_select < p_triangles_) {
    glm::vec3 point;
    glm::vec2 b;
    float area_pdf;
    const size_t i = triangle_point(position, u_select / p_triangles_, u, reuse_select, &point, &b, &area_pdf);
    return triangle_sample(position, i, point, b, area_pdf, out);
  }
  u_select -= p_triangles_;
  if (u_select < p_environment_) {
    if (reuse_select) u.x = std::min(u_select / p_environment_, 0x1.fffffep-1f);
    return sample_environment(u, sky, out);
  }
  u_select -= p_environment_;
  if (p_punctual_ <= 0.0f) return false;
  return sample_punctual(position, std::min(u_select / p_punctual_, 0x1.fffffep-1f), out);
}

// Pairs triangles [first, end) of one mesh (one emission, so one power per area): triangles t and
// t + 1 form a parallelogram when they share two corners and the other two sum to the shared ones.
void LightSampler::find_parallelograms(size_t first, size_t end) {
  for (size_t t = first; t + 1 < end;) {
    const EmissiveTriangle &a = triangles_[t], &b = triangles_[t + 1];
    const glm::vec3 pa[3] = {a.p0, a.p0 + a.e1, a.p0 + a.e2}, pb[3] = {b.p0, b.p0 + b.e1, b.p0 + b.e2};
    // A corner shared with b is one of b's corners exactly (both come from the same positions).
    int shared_a[3], shared_count = 0, b_used = 0;
    for (int i = 0; i < 3; ++i) {
      shared_a[i] = -1;
      for (int j = 0; j < 3; ++j)
        if (pa[i] == pb[j]) shared_a[i] = j;
      if (shared_a[i] >= 0) ++shared_count, b_used |= 1 << shared_a[i];
    }
    if (shared_count != 2 || !(a.area > 0.0f) || !(b.area > 0.0f)) {
      ++t;
      continue;
    }
    const int c = shared_a[0] < 0 ? 0 : shared_a[1] < 0 ? 1 : 2;  // a's own corner
    const int d = (b_used & 1) == 0 ? 0 : (b_used & 2) == 0 ? 1 : 2;   // b's own corner
    const glm::vec3 s1 = pa[(c + 1) % 3], s2 = pa[(c + 2) % 3];
    const float scale = std::max({glm::length(s1 - pa[c]), glm::length(s2 - pa[c]), glm::length(s1 - s2)});
    if (!(glm::length(pa[c] + pb[d] - s1 - s2) <= 1e-5f * scale)) {
      ++t;
      continue;
    }
    Parallelogram q;
    q.first = t;
    q.origin = pa[c];
    q.edge_u = s1 - pa[c];
    q.edge_v = s2 - pa[c];
    // Selection within a mesh goes by power, and power per area is the mesh's: the first
    // triangle's share of the pair is its share of the area.
    const float share_first = a.area / (a.area + b.area);
    q.share_of[0] = share_first;
    q.share_of[1] = 1.0f - share_first;
    q.rectangle = std::abs(glm::dot(q.edge_u, q.edge_v)) <= 1e-5f * glm::length(q.edge_u) * glm::length(q.edge_v);
    q.front = front_side(t, t + 2);
    q.inv_length2_u = 1.0f / glm::dot(q.edge_u, q.edge_u);
    q.inv_length2_v = 1.0f / glm::dot(q.edge_v, q.edge_v);
    q.diagonal2 = glm::dot(q.edge_u + q.edge_v, q.edge_u + q.edge_v);
    // The pair's corners by role: 0 the triangle's own corner, 1 origin + edge_u, 2 origin + edge_v;
    // their weights as affine functions (1, a, b) of the pair's coordinates, on either triangle.
    // The first triangle is origin, +u, +v: weights 1 - a - b, a, b. The second is origin + u + v,
    // +u, +v: weights a + b - 1, 1 - b, 1 - a.
    constexpr float kRoleWeight[2][3][3] = {{{1, -1, -1}, {0, 1, 0}, {0, 0, 1}}, {{-1, 1, 1}, {1, 0, -1}, {1, -1, 0}}};
    for (int k = 1; k < 3; ++k) {
      const int role_a = k == c ? 0 : k == (c + 1) % 3 ? 1 : 2;
      const int role_b = k == d ? 0 : pb[k] == s1 ? 1 : 2;
      for (int j = 0; j < 3; ++j) {
        q.bary_coef[0][k - 1][j] = kRoleWeight[0][role_a][j];
        q.bary_coef[1][k - 1][j] = kRoleWeight[1][role_b][j];
      }
    }
    triangles_[t].parallelogram = triangles_[t + 1].parallelogram = static_cast<int>(parallelograms_.size());
    parallelograms_.push_back(q);
    t += 2;
  }
}

size_t LightSampler::pair_triangle(const Parallelogram& q, glm::vec2 uv, glm::vec2* barycentrics) const {
  // Which triangle is a coin flip per sample: its coefficients are looked up, not branched on.
  const float a = uv.x, b = uv.y;
  const int second = !(a + b <= 1.0f);
  const float(*coef)[3] = q.bary_coef[second];
  const float b1 = coef[0][0] + coef[0][1] * a + coef[0][2] * b, b2 = coef[1][0] + coef[1][1] * a + coef[1][2] * b;
  *barycentrics = glm::vec2(std::min(std::max(b1, 0.0f), 1.0f), std::min(std::max(b2, 0.0f), 1.0f));
  return q.first + static_cast<size_t>(second);
}

void LightSampler::build_near_field_clusters(const std::vector<float>& powers) {
  std::vector<Cluster> clusters;
  for (size_t i = 0; i < triangles_.size();) {
    Cluster c;
    c.first = i;
    size_t end = i;
    while (end < triangles_.size() && triangles_[end].mesh == triangles_[i].mesh) ++end;
    glm::vec3 lo(kInf), hi(-kInf);
    for (size_t t = i; t < end; ++t) {
      const EmissiveTriangle& e = triangles_[t];
      for (glm::vec3 p : {e.p0, e.p0 + e.e1, e.p0 + e.e2}) lo = glm::min(lo, p), hi = glm::max(hi, p);
    }
    c.lo = lo;
    c.hi = hi;
    c.floor2 = std::max(0.01f * 0.25f * glm::dot(hi - lo, hi - lo), 1e-12f);
    c.triangles = Distribution1D(powers.data() + i, end - i);
    c.front = front_side(i, end);
    for (size_t t = i; t < end; ++t) c.power += powers[t];
    if (c.triangles.valid() && std::isfinite(c.power) && std::isfinite(c.floor2)) clusters.push_back(std::move(c));
    i = end;
  }
  double total = 0;
  for (const Cluster& c : clusters) total += c.power;
  // One mesh (nothing to choose) or many (the per-sample loop over them would cost too much).
  if (clusters.size() < 2 || clusters.size() > kMaxNearFieldClusters || !(total > 0.0)) return;
  for (Cluster& c : clusters) c.power_share = c.power / total;
  clusters_ = std::move(clusters);
  triangle_cluster_.assign(triangles_.size(), -1);
  for (size_t c = 0; c < clusters_.size(); ++c)
    for (size_t t = clusters_[c].first; t < clusters_[c].first + clusters_[c].triangles.size(); ++t)
      triangle_cluster_[t] = static_cast<int>(c);
}

// One-sided when triangles [first, end) lie in one plane with one facing and emit from the front only.
LightSampler::FrontSide LightSampler::front_side(size_t first, size_t end) const {
  const EmissiveTriangle& a = triangles_[first];
  if (a.material->double_sided || !(a.area > 0.0f)) return FrontSide{};
  float extent = 0.0f;
  for (size_t t = first; t < end; ++t) extent = std::max({extent, glm::length(triangles_[t].e1), glm::length(triangles_[t].e2)});
  for (size_t t = first; t < end; ++t) {
    const EmissiveTriangle& e = triangles_[t];
    if (!(e.area > 0.0f) || glm::dot(e.normal, a.normal) < 1.0f - 1e-5f) return FrontSide{};
    for (glm::vec3 p : {e.p0, e.p0 + e.e1, e.p0 + e.e2})
      if (!(std::abs(glm::dot(p - a.p0, a.normal)) <= 1e-5f * extent)) return FrontSide{};
  }
  return FrontSide{true, a.normal, a.p0};
}

void LightSampler::cluster_probabilities(glm::vec3 from, float* out) const {
  // Power shares and near-field weights over the clusters that can light `from`.
  bool lit[kMaxNearFieldClusters];
  double power = 0.0;
  for (size_t c = 0; c < clusters_.size(); ++c) {
    lit[c] = clusters_[c].front.can_light(from);
    if (lit[c]) power += clusters_[c].power_share;
  }
  if (!(power > 0.0)) {  // behind every panel: nothing can light it, any choice will do
    for (size_t c = 0; c < clusters_.size(); ++c) lit[c] = true;
    power = 1.0;
  }
  float sum = 0.0f;
  for (size_t c = 0; c < clusters_.size(); ++c) {
    const glm::vec3 d = glm::max(glm::max(clusters_[c].lo - from, from - clusters_[c].hi), glm::vec3(0.0f));
    out[c] = lit[c] ? clusters_[c].power / (glm::dot(d, d) + clusters_[c].floor2) : 0.0f;
    sum += out[c];
  }
  const bool near_valid = sum > 0.0f && std::isfinite(sum);
  for (size_t c = 0; c < clusters_.size(); ++c) {
    const float share = lit[c] ? static_cast<float>(clusters_[c].power_share / power) : 0.0f;
    out[c] = 0.5f * share + (near_valid ? 0.5f * out[c] / sum : 0.5f * share);
  }
}

size_t LightSampler::pick_triangle(glm::vec3 from, float u_select, float* u_remapped, float* pmf) const {
  if (clusters_.empty()) return triangle_dist_.sample(u_select, u_remapped, pmf);
  float p[kMaxNearFieldClusters];
  cluster_probabilities(from, p);
  size_t c = 0;
  float lo = 0.0f;
  while (c + 1 < clusters_.size() && !(u_select < lo + p[c])) lo += p[c++];
  while (!(p[c] > 0.0f) && c > 0) lo -= p[--c];  // rounding left u past the last nonzero cluster
  const float u = std::min(std::max((u_select - lo) / p[c], 0.0f), 0x1.fffffep-1f);
  float pmf_in;
  const size_t i = clusters_[c].first + clusters_[c].triangles.sample(u, u_remapped, &pmf_in);
  *pmf = p[c] * pmf_in;
  return i;
}

float LightSampler::triangle_selection_pmf(size_t light, glm::vec3 from) const {
  if (clusters_.empty()) return triangle_dist_.pmf(light);
  if (triangle_cluster_[light] < 0) return 0.0f;  // a mesh without power
  float p[kMaxNearFieldClusters];
  cluster_probabilities(from, p);
  const Cluster& c = clusters_[static_cast<size_t>(triangle_cluster_[light])];
  return p[triangle_cluster_[light]] * c.triangles.pmf(light - c.first);
}

size_t LightSampler::sample_triangle_point(glm::vec3 from, float u_select, glm::vec2 u, glm::vec3* point,
                                           glm::vec2* bary, float* area_pdf) const {
  return triangle_point(from, u_select, u, false, point, bary, area_pdf);
}

size_t LightSampler::sample_triangle_point(glm::vec3 from, glm::vec2 u, glm::vec3* point, glm::vec2* bary,
                                           float* area_pdf) const {
  return triangle_point(from, u.x, u, true, point, bary, area_pdf);
}

size_t LightSampler::triangle_point(glm::vec3 from, float u_select, glm::vec2 u, bool reuse_select, glm::vec3* point,
                                    glm::vec2* bary, float* area_pdf) const {
  float pmf;
  const size_t i = pick_triangle(from, u_select, reuse_select ? &u.x : nullptr, &pmf);
  if (triangles_[i].parallelogram >= 0) {
    const Parallelogram& q = parallelograms_[static_cast<size_t>(triangles_[i].parallelogram)];
    const float share = q.share(i);
    // With the shared selection u.x spans the pair's contiguous share of the selection: [0, 1)
    // over both triangles, so the pair is sampled as one.
    const glm::vec2 v(reuse_select ? std::min(q.share_start(i) + u.x * share, 0x1.fffffep-1f) : u.x,
                      u.y);
    SphericalRectangle sr;
    if (solid_angle_sampling(q, from, &sr)) {
      *point = sr.sample(v);
      const glm::vec3 r = *point - q.origin;
      const glm::vec2 uv = glm::clamp(glm::vec2(glm::dot(r, q.edge_u) * q.inv_length2_u, glm::dot(r, q.edge_v) * q.inv_length2_v),
                                      0.0f, 1.0f);
      const size_t j = pair_triangle(q, uv, bary);
      // The area density that is 1 / solid angle in solid angle (cos / r^2 of the point).
      const glm::vec3 d = *point - from;
      const float dist2 = glm::dot(d, d);
      const float cos_light = std::abs(glm::dot(d, triangles_[j].normal)) / std::sqrt(dist2);
      *area_pdf = dist2 > 0.0f ? pmf / share / sr.solid_angle() * cos_light / dist2 : 0.0f;
      return j;
    }
    if (reuse_select) {
      // Both triangles have the same power per area, so the density is the same on either.
      *point = q.origin + v.x * q.edge_u + v.y * q.edge_v;
      *area_pdf = triangles_[i].area > 0.0f ? pmf / triangles_[i].area : 0.0f;
      return pair_triangle(q, v, bary);
    }
  }
  const EmissiveTriangle& e = triangles_[i];
  const glm::vec2 b = sample_triangle_barycentrics(u);
  *point = e.p0 + b.x * e.e1 + b.y * e.e2;
  *bary = b;
  *area_pdf = e.area > 0.0f ? pmf / e.area : 0.0f;
  return i;
}

// The light sample toward `point` on emissive triangle `light`, drawn with area pdf `area_pdf`.
bool LightSampler::triangle_sample(glm::vec3 position, size_t light, glm::vec3 point, glm::vec2 b, float area_pdf,
                                   LightSample* out) const {
  const EmissiveTriangle& e = triangles_[light];
  glm::vec3 d = point - position;
  float dist2 = glm::dot(d, d);
  if (!(dist2 > 0.0f) || !(area_pdf > 0.0f)) return false;
  float dist = std::sqrt(dist2);
  glm::vec3 wi = d / dist;
  float cos_light = -glm::dot(wi, e.normal);
  if (e.material->double_sided) cos_light = std::abs(cos_light);
  if (cos_light <= 1e-7f) return false;  // the back of a one-sided emitter, or edge-on
  glm::vec2 uv0(0.0f), uv1(0.0f);
  if (e.textured) {
    const Mesh& mesh = scene_.meshes[e.mesh];
    const glm::uvec3& tri = mesh.triangles[e.prim];
    const float b0 = 1.0f - b.x - b.y;
    if (!mesh.uv0.empty()) uv0 = mesh.uv0[tri.x] * b0 + mesh.uv0[tri.y] * b.x + mesh.uv0[tri.z] * b.y;
    if (!mesh.uv1.empty()) uv1 = mesh.uv1[tri.x] * b0 + mesh.uv1[tri.y] * b.x + mesh.uv1[tri.z] * b.y;
  }
  out->wi = wi;
  out->distance = dist;
  out->radiance = eval_emission(scene_, *e.material, uv0, uv1);
  out->pdf = p_triangles_ * area_pdf * dist2 / cos_light;
  out->delta = false;
  out->point = point;
  out->normal = e.normal;
  return true;
}

float LightSampler::pdf_triangle(unsigned mesh, unsigned prim, glm::vec3 from, glm::vec3 point,
                                 glm::vec3 face_normal) const {
  if (p_triangles_ <= 0.0f || mesh >= mesh_light_offset_.size() || mesh_light_offset_[mesh] < 0) return 0.0f;
  const EmissiveTriangle& e = triangles_[static_cast<size_t>(mesh_light_offset_[mesh]) + prim];
  if (!(e.area > 0.0f)) return 0.0f;
  glm::vec3 d = point - from;
  float dist2 = glm::dot(d, d);
  float cos_light = std::abs(glm::dot(d, face_normal)) / std::sqrt(dist2);
  if (!(cos_light > 0.0f)) return 0.0f;
  const size_t light = static_cast<size_t>(mesh_light_offset_[mesh]) + prim;
  const float pmf = triangle_selection_pmf(light, from);
  if (e.parallelogram >= 0) {
    const Parallelogram& q = parallelograms_[static_cast<size_t>(e.parallelogram)];
    SphericalRectangle sr;
    if (solid_angle_sampling(q, from, &sr))
      return p_triangles_ * pmf / q.share(light) / sr.solid_angle();
  }
  return p_triangles_ * pmf / e.area * dist2 / cos_light;
}

glm::vec3 LightSampler::sample_environment_direction(glm::vec2 u, float* pdf, glm::vec2* uv_out) const {
  float pdf_uv;
  glm::vec2 uv = env_dist_.sample(u, &pdf_uv);
  glm::vec3 wi = equirect_direction(uv);
  float sin_theta = std::sin(uv.y * kPi);
  *pdf = sin_theta > 0.0f ? pdf_uv / (2.0f * kPi * kPi * sin_theta) : 0.0f;
  if (uv_out) *uv_out = uv;
  return wi;
}

float LightSampler::environment_direction_pdf(glm::vec3 direction) const {
  if (!env_) return 0.0f;
  return environment_density(equirect_uv(direction), direction);
}

// The density at a direction whose place on the map is known (no atan2 and acos again); sin theta
// from the direction, exact near the poles.
float LightSampler::environment_density(glm::vec2 uv, glm::vec3 direction) const {
  const float sin_theta = std::sqrt(direction.x * direction.x + direction.z * direction.z);
  return sin_theta > 0.0f ? env_dist_.pdf(uv) / (2.0f * kPi * kPi * sin_theta) : 0.0f;
}

// With a learned sky, u.x picks the strategy (the sky's share of [0, 1) the learned one) and,
// rescaled, stays the chosen strategy's first coordinate; either direction's pdf is the mixture's.
// The sampled direction's place on the map serves both densities and the radiance.
bool LightSampler::sample_environment(glm::vec2 u, const VisibleSky* sky, LightSample* out) const {
  float pdf;
  glm::vec3 wi;
  glm::vec2 uv;
  if (sky && sky->learned() && sky->share() > 0.0f) {
    const float share = sky->share();
    float learned_pdf, radiance_pdf;
    if (u.x < share) {
      wi = sky->sample(glm::vec2(u.x / share, u.y), &learned_pdf, &uv);
      radiance_pdf = environment_density(uv, wi);
    } else {
      wi = sample_environment_direction(glm::vec2(std::min((u.x - share) / (1.0f - share), 0x1.fffffep-1f), u.y),
                                        &radiance_pdf, &uv);
      learned_pdf = sky->density(uv, wi);
    }
    pdf = share * learned_pdf + (1.0f - share) * radiance_pdf;
  } else {
    wi = sample_environment_direction(u, &pdf, &uv);
  }
  if (!(pdf > 0.0f)) return false;
  out->wi = wi;
  out->distance = kInf;
  out->radiance = glm::vec3(sample_texture(env_->image, uv)) * env_->strength;
  out->pdf = p_environment_ * pdf;
  out->delta = false;
  return true;
}

float LightSampler::pdf_environment(glm::vec3 direction, const VisibleSky* sky) const {
  if (!env_) return 0.0f;
  return pdf_environment_at(equirect_uv(direction), direction, sky);
}

glm::vec3 LightSampler::environment_hit(glm::vec3 direction, const VisibleSky* sky, float* pdf) const {
  *pdf = 0.0f;
  if (!env_) return glm::vec3(0.0f);
  const glm::vec2 uv = equirect_uv(direction);
  *pdf = pdf_environment_at(uv, direction, sky);
  return glm::vec3(sample_texture(env_->image, uv)) * env_->strength;
}

float LightSampler::pdf_environment_at(glm::vec2 uv, glm::vec3 direction, const VisibleSky* sky) const {
  const float radiance_pdf = environment_density(uv, direction);
  if (!(sky && sky->learned() && sky->share() > 0.0f)) return p_environment_ * radiance_pdf;
  const float share = sky->share();
  return p_environment_ * (share * sky->density(uv, direction) + (1.0f - share) * radiance_pdf);
}

glm::vec3 LightSampler::environment_radiance(glm::vec3 direction) const {
  if (!env_) return glm::vec3(0.0f);
  return glm::vec3(sample_texture(env_->image, equirect_uv(direction))) * env_->strength;
}

namespace {
// A directional light's sample, the same from every point: towards where its light comes from, at
// infinity, irradiance E x colour; `pdf` the probability it was taken with.
LightSample directional_sample(const PunctualLight& light, float pdf) {
  LightSample out;
  out.wi = -glm::normalize(light.direction);
  out.distance = kInf;
  out.radiance = light.color * light.intensity;
  out.pdf = pdf;
  out.delta = true;
  return out;
}
}  // namespace

bool LightSampler::fixed_light_sample(size_t index, glm::vec3 position, LightSample* out) const {
  return punctual_sample(*fixed_[index], position, 1.0f, out);
}

bool LightSampler::sample_punctual(glm::vec3 position, float u_select, LightSample* out) const {
  size_t index = std::min(static_cast<size_t>(u_select * punctual_.size()), punctual_.size() - 1);
  return punctual_sample(*punctual_[index], position, p_punctual_ / static_cast<float>(punctual_.size()), out);
}

// A punctual light's sample at `position`, taken with probability `pdf`.
bool LightSampler::punctual_sample(const PunctualLight& light, glm::vec3 position, float pdf, LightSample* out) {
  if (light.type == PunctualLight::Type::Directional) {
    *out = directional_sample(light, pdf);
    return true;
  }
  glm::vec3 power = light.color * light.intensity;
  out->delta = true;
  out->pdf = pdf;
  glm::vec3 d = light.position - position;
  float dist2 = glm::dot(d, d);
  if (!(dist2 > 0.0f)) return false;
  float dist = std::sqrt(dist2);
  out->wi = d / dist;
  out->distance = dist;
  out->point = light.position;  // no surface: out->normal stays 0, so shadow rays aim at it unoffset
  float falloff = range_window(dist, light.range) / dist2;
  if (light.type == PunctualLight::Type::Spot) falloff *= spot_attenuation(light, -out->wi);
  out->radiance = power * falloff;
  return falloff > 0.0f;
}

bool LightSampler::sample_emission(glm::vec2 u_select, glm::vec2 u_position, glm::vec2 u_direction,
                                   EmittedPhoton* out) const {
  if (!emission_dist_.valid()) return false;
  float pmf = 0.0f;
  const size_t choice = emission_dist_.sample(u_select.x, nullptr, &pmf);
  if (!(pmf > 0.0f)) return false;
  if (choice == 0) {
    if (!emit_from_triangle(u_select, u_position, u_direction, out)) return false;
  } else if (choice == 1) {
    float pdf = 0.0f;
    const glm::vec3 toward_light = sample_environment_direction(u_direction, &pdf);
    if (!(pdf > 0.0f)) return false;
    *out = emit_from_infinity(toward_light, environment_radiance(toward_light), pdf, u_position);
  } else {
    const size_t index = choice - 2;
    const bool fixed = index >= punctual_.size();
    const PunctualLight& light = fixed ? *fixed_[index - punctual_.size()] : *punctual_[index];
    const glm::vec3 power = light.color * light.intensity;
    if (light.type == PunctualLight::Type::Directional) {
      *out = emit_from_infinity(-glm::normalize(light.direction), power, 1.0f, u_position);
    } else {  // point and spot: uniform directions, the spot's cone weighting the flux
      out->origin = light.position;
      out->direction = sample_uniform_sphere(u_direction);
      float scale = 4.0f * kPi;
      if (light.type == PunctualLight::Type::Spot) scale *= spot_attenuation(light, out->direction);
      out->flux = power * scale;
    }
  }
  out->flux /= pmf;
  return max_component(out->flux) > 0.0f && is_finite(out->flux) && is_finite(out->origin);
}

// A uniform point on a triangle picked by power and a cosine-distributed direction on an
// emitting side: flux = L pi area sides / the triangle's probability.
bool LightSampler::emit_from_triangle(glm::vec2 u_select, glm::vec2 u_position, glm::vec2 u_direction,
                                      EmittedPhoton* out) const {
  float pmf = 0.0f;
  const size_t index = triangle_dist_.sample(u_select.y, nullptr, &pmf);
  const EmissiveTriangle& e = triangles_[index];
  if (!(pmf > 0.0f)) return false;
  const glm::vec2 b = sample_triangle_barycentrics(u_position);
  out->origin = e.p0 + b.x * e.e1 + b.y * e.e2;
  glm::vec3 normal = e.normal;
  float sides = 1.0f;
  if (e.material->double_sided) {  // either side, by the direction's first number
    sides = 2.0f;
    if (u_direction.x < 0.5f) {
      normal = -normal;
      u_direction.x *= 2.0f;
    } else {
      u_direction.x = 2.0f * u_direction.x - 1.0f;
    }
    u_direction.x = std::min(u_direction.x, 0x1.fffffep-1f);
  }
  out->direction = Frame::from_normal(normal).to_world(sample_cosine_hemisphere(u_direction));
  out->origin += normal * (1e-4f * std::max(1.0f, max_component(glm::abs(out->origin))));
  out->flux = e.material->emissive * (kPi * e.area * sides / pmf);
  return true;
}

EmittedPhoton LightSampler::emit_from_infinity(glm::vec3 toward_light, glm::vec3 radiance, float pdf,
                                               glm::vec2 u_position) const {
  const Frame frame = Frame::from_normal(toward_light);
  const glm::vec2 disc = sample_concentric_disk(u_position) * scene_radius_;
  EmittedPhoton photon;
  photon.origin = scene_center_ + scene_radius_ * toward_light + frame.t * disc.x + frame.b * disc.y;
  photon.direction = -toward_light;
  photon.flux = radiance * (kPi * scene_radius_ * scene_radius_ / pdf);
  photon.from_infinity = true;
  return photon;
}

// The fixed lights count too: they are outside the choice, not outside the light.
float environment_light_share(const Scene& scene) {
  if (!scene.environment) return 0.0f;
  const LightSampler lights(scene);
  double total = lights.estimated_power(), environment = lights.estimated_environment_power();
  return total > 0.0 && std::isfinite(total) ? static_cast<float>(environment / total) : 0.0f;
}

}  // namespace pxf
