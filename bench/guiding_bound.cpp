// How far first-vertex path guiding can go (guiding_bound.h).
#include "bench/guiding_bound.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "pathtracer/bsdf.h"
#include "pathtracer/guiding_field.h"
#include "pathtracer/integrator.h"
#include "pathtracer/rng.h"
#include "pathtracer/sampling.h"

namespace pxf {

double cell_estimator_variance(const std::vector<DirectionCell>& cells, const std::vector<double>& q) {
  double mean = 0.0, second = 0.0;
  for (size_t i = 0; i < cells.size(); ++i) {
    const DirectionCell& c = cells[i];
    mean += c.cosine_share * c.mean;
    const double numerator = c.cosine_share * c.cosine_share * c.second_moment;
    if (numerator <= 0.0) continue;
    if (!(q[i] > 0.0)) return std::numeric_limits<double>::infinity();
    second += numerator / q[i];
  }
  return second - mean * mean;
}

std::vector<double> field_guide(const std::vector<DirectionCell>& cells, double alpha) {
  std::vector<double> q(cells.size());
  for (size_t i = 0; i < cells.size(); ++i) q[i] = alpha * cells[i].guide_share + (1.0 - alpha) * cells[i].cosine_share;
  return q;
}

std::vector<double> known_light_guide(const std::vector<DirectionCell>& cells, double alpha) {
  double light = 0.0;
  for (const DirectionCell& c : cells) light += c.cosine_share * std::max(c.mean, 0.0);
  std::vector<double> q(cells.size());
  for (size_t i = 0; i < cells.size(); ++i) {
    const DirectionCell& c = cells[i];
    const double guided = light > 0.0 ? c.cosine_share * std::max(c.mean, 0.0) / light : c.cosine_share;
    q[i] = alpha * guided + (1.0 - alpha) * c.cosine_share;
  }
  return q;
}

std::vector<double> least_variance_guide(const std::vector<DirectionCell>& cells) {
  double total = 0.0;
  for (const DirectionCell& c : cells) total += c.cosine_share * std::sqrt(std::max(c.second_moment, 0.0));
  std::vector<double> q(cells.size(), 0.0);
  if (!(total > 0.0)) {
    for (size_t i = 0; i < cells.size(); ++i) q[i] = cells[i].cosine_share;
    return q;
  }
  for (size_t i = 0; i < cells.size(); ++i)
    q[i] = cells[i].cosine_share * std::sqrt(std::max(cells[i].second_moment, 0.0)) / total;
  return q;
}

double guide_variance_floor(const std::vector<double>& second_moments, const std::vector<double>& means) {
  if (second_moments.empty()) return 0.0;
  double root = 0.0, mean = 0.0;
  for (size_t i = 0; i < second_moments.size(); ++i) {
    root += std::sqrt(std::max(second_moments[i], 0.0));
    mean += means[i];
  }
  root /= second_moments.size();
  mean /= second_moments.size();
  return root * root - mean * mean;
}

namespace {

// A first vertex: where a camera ray meets a surface with a diffuse lobe.
struct BoundPoint {
  int x = 0, y = 0;
  glm::vec3 position{0.0f}, normal{0.0f}, geometric_normal{0.0f};
  double albedo = 0.0;  // luminance of the diffuse albedo
};

// Only points whose diffuse lobe carries at least this share of the BSDF: guiding serves the diffuse lobe.
constexpr float kMinDiffuseShare = 0.5f;

bool find_point(const PathTracer& tracer, const Scene& scene, int width, int height, int x, int y, BoundPoint* point) {
  const Ray ray = camera_ray(scene.camera, width, height, x + 0.5f, y + 0.5f);
  const Hit hit = tracer.geometry().intersect(ray);
  if (!hit.valid()) return false;
  const SurfacePoint sp = tracer.geometry().surface_point(hit, ray);
  const BsdfParams material = eval_material(scene, *sp.material, sp.uv0, sp.uv1, sp.color);
  const float diffuse = (1.0f - material.metallic) * (1.0f - material.transmission);
  if (diffuse < kMinDiffuseShare) return false;
  glm::vec3 n = sp.shading_normal;
  if (glm::dot(n, ray.direction) > 0.0f) n = -n;
  glm::vec3 ng = sp.geometric_normal;
  if (glm::dot(ng, n) < 0.0f) ng = -ng;
  *point = BoundPoint{x, y, sp.position, n, ng, double(luminance(material.base_color) * diffuse)};
  return true;
}

// A camera at `origin` looking along `forward` with 90 degrees of view: its pixels are one cube face.
Camera cube_face_camera(glm::vec3 origin, glm::vec3 forward, glm::vec3 up) {
  Camera camera;
  const glm::vec3 z = -forward, x = glm::cross(up, z);
  camera.camera_to_world = glm::mat4(glm::vec4(x, 0.0f), glm::vec4(up, 0.0f), glm::vec4(z, 0.0f), glm::vec4(origin, 1.0f));
  camera.yfov = 0.5f * 3.14159265358979f;
  return camera;
}

// The indirect light of camera paths that start at a point: each path's light less the light its
// first segment sees directly (NEE's at the point), both traced with the same random numbers. The
// paths are one vertex shorter than the render's, since the point is their first vertex.
class IndirectLight {
 public:
  IndirectLight(const PathTracer& tracer, const TraceParams& params) : tracer_(tracer), full_(params) {
    full_.guiding = GuidingMode::Off;
    full_.sampler = SamplerType::Independent;
    full_.max_vertices = std::max(2, params.max_vertices - 1);
    full_.rr_start_vertex = std::max(2, params.rr_start_vertex - 1);
    direct_ = full_;
    direct_.max_vertices = 2;
  }
  // out[i]: the luminance of the i-th pixel's path of `rect` (frame `frame`, seed `seed`).
  void trace(const Camera& camera, int width, int height, const PixelRect& rect, uint32_t frame, uint64_t seed,
             double* out) const {
    std::vector<PathSample> with(static_cast<size_t>(rect.count())), without(with.size());
    TraceParams full = full_, direct = direct_;
    full.seed = direct.seed = seed;
    tracer_.trace_pixels(camera, width, height, rect, frame, full, with.data());
    tracer_.trace_pixels(camera, width, height, rect, frame, direct, without.data());
    for (size_t i = 0; i < with.size(); ++i)
      out[i] = double(luminance(with[i].lv + with[i].hv)) - luminance(without[i].lv + without[i].hv);
  }

 private:
  const PathTracer& tracer_;
  TraceParams full_, direct_;
};

// Directions drawn by cosine sampling, each with floor_paths paths in exactly that direction (a
// camera of negligible field of view, one pixel per path along its row): per direction the mean of
// the paths' indirect light and of its square, for guide_variance_floor.
void trace_floor_directions(const PathTracer& tracer, const BoundPoint& p, const TraceParams& params,
                            const GuidingBoundSettings& s, std::vector<double>* second_moments, std::vector<double>* means) {
  const Frame frame = Frame::from_normal(p.normal);
  const glm::vec3 origin = offset_ray_origin(p.position, p.geometric_normal, p.normal);
  const IndirectLight indirect(tracer, params);
  const int k = s.floor_paths;
  second_moments->assign(static_cast<size_t>(s.floor_directions), 0.0);
  means->assign(static_cast<size_t>(s.floor_directions), 0.0);
  tbb::parallel_for(0, s.floor_directions, [&](int i) {
    Rng rng(s.seed ^ 0x666c6f6f72ULL, static_cast<uint64_t>(i), 0);  // "floor"
    const glm::vec3 d = frame.to_world(sample_cosine_hemisphere(rng.next_2d()));
    const glm::vec3 side = std::abs(d.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
    Camera camera = cube_face_camera(origin, d, glm::normalize(glm::cross(glm::cross(d, side), d)));
    camera.yfov = 1e-6f;
    std::vector<double> light(static_cast<size_t>(k));
    indirect.trace(camera, k, 1, PixelRect{0, 0, k, 1}, 0, s.seed * 7919u + 104729u + static_cast<uint64_t>(i), light.data());
    double sum = 0.0, sum2 = 0.0;
    for (double l : light) {
      sum += l;
      sum2 += l * l;
    }
    (*means)[static_cast<size_t>(i)] = sum / k;
    (*second_moments)[static_cast<size_t>(i)] = sum2 / k;
  });
}

// The hemisphere's cells around a point, each traced with paths_per_cell paths.
std::vector<DirectionCell> trace_cells(const PathTracer& tracer, const GuidingField& field, const BoundPoint& p,
                                       const TraceParams& params, const GuidingBoundSettings& s, double* alpha) {
  const Frame frame = Frame::from_normal(p.normal);
  const glm::vec3 origin = offset_ray_origin(p.position, p.geometric_normal, p.normal);
  const glm::vec3 forward[5] = {frame.n, frame.t, -frame.t, frame.b, -frame.b};
  const glm::vec3 up[5] = {frame.t, frame.n, frame.n, frame.n, frame.n};
  const IndirectLight indirect(tracer, params);
  const GuidingField::Distribution guide = field.trained() ? field.distribution(p.position, p.geometric_normal)
                                                           : GuidingField::Distribution();
  const bool guided = field.trained() && guide.learned();
  *alpha = guided ? double(guide.alpha()) * guide.share() : 0.0;

  const int n = s.face_cells;
  std::vector<DirectionCell> cells;
  for (int f = 0; f < 5; ++f) {
    const Camera camera = cube_face_camera(origin, forward[f], up[f]);
    const int rows = f == 0 ? n : n / 2;  // a side face's upper half looks above the surface
    std::vector<DirectionCell> face(static_cast<size_t>(rows) * n);
    tbb::parallel_for(0, rows, [&](int row) {
      std::vector<double> light(static_cast<size_t>(n));
      for (int k = 0; k < s.paths_per_cell; ++k) {
        indirect.trace(camera, n, n, PixelRect{0, row, n, row + 1}, static_cast<uint32_t>(k),
                       s.seed * 7919u + static_cast<uint64_t>(k), light.data());
        for (int i = 0; i < n; ++i) {
          face[size_t(row) * n + i].mean += light[i];
          face[size_t(row) * n + i].second_moment += light[i] * light[i];
        }
      }
    });
    const glm::mat3 basis(camera.camera_to_world);
    for (int row = 0; row < rows; ++row)
      for (int col = 0; col < n; ++col) {
        const double u = 2.0 * (col + 0.5) / n - 1.0, v = 1.0 - 2.0 * (row + 0.5) / n;
        const glm::vec3 d = glm::normalize(basis * glm::vec3(float(u), float(v), -1.0f));
        const double cosine = glm::dot(d, p.normal);
        if (cosine <= 0.0) continue;
        const double solid_angle = (4.0 / (double(n) * n)) / std::pow(1.0 + u * u + v * v, 1.5);
        DirectionCell c = face[size_t(row) * n + col];
        c.mean /= s.paths_per_cell;
        c.second_moment /= s.paths_per_cell;
        c.cosine_share = cosine * solid_angle / 3.14159265358979;
        c.guide_share = guided ? double(guide.pdf(d)) * solid_angle : 0.0;
        cells.push_back(c);
      }
  }
  double total = 0.0;  // the cube's cells cover the hemisphere up to discretisation: make b a distribution
  for (const DirectionCell& c : cells) total += c.cosine_share;
  for (DirectionCell& c : cells) c.cosine_share /= total;
  return cells;
}

}  // namespace

GuidingBound measure_guiding_bound(const Scene& scene, const TraceParams& params, int width, int height,
                                   const GuidingBoundSettings& s) {
  // The field as the renderer trains it.
  TraceParams guided = params;
  guided.guiding = GuidingMode::On;
  ProgressiveRenderer trainer(scene, guided, width, height);
  for (int i = 0; i < s.train_frames; ++i) trainer.add_frame();
  const std::vector<uint8_t> bytes = trainer.guiding_field();
  const GuidingField field = GuidingField::deserialize(bytes.data(), bytes.size());

  PathTracer tracer(scene);
  tbb::task_arena arena(params.threads > 0 ? params.threads : tbb::task_arena::automatic);
  Rng rng(s.seed, 0, 0);
  GuidingBound bound;
  bound.chains_left_out = tracer.has_perfect_specular() && (params.specular_sampling || params.specular_chains);
  std::vector<GuidingBoundPoint>& out = bound.points;
  for (int attempt = 0; attempt < 100 * s.points && static_cast<int>(out.size()) < s.points; ++attempt) {
    const int x = std::min(width - 1, int(rng.next_float() * width));
    const int y = std::min(height - 1, int(rng.next_float() * height));
    BoundPoint p;
    if (!find_point(tracer, scene, width, height, x, y, &p)) continue;
    double alpha = 0.0;
    std::vector<DirectionCell> cells;
    std::vector<double> second_moments, means;
    arena.execute([&] {
      cells = trace_cells(tracer, field, p, params, s, &alpha);
      trace_floor_directions(tracer, p, params, s, &second_moments, &means);
    });
    GuidingBoundPoint r;
    r.x = x;
    r.y = y;
    const double weight = p.albedo * p.albedo;
    for (const DirectionCell& c : cells) {
      r.indirect += c.cosine_share * c.mean * p.albedo;
      r.deeper += c.cosine_share * (c.second_moment - c.mean * c.mean) * weight;
    }
    std::vector<double> cosine(cells.size());
    for (size_t i = 0; i < cells.size(); ++i) cosine[i] = cells[i].cosine_share;
    r.cosine = cell_estimator_variance(cells, cosine) * weight;
    r.field = cell_estimator_variance(cells, field_guide(cells, alpha)) * weight;
    r.known_light = cell_estimator_variance(cells, known_light_guide(cells, 0.5)) * weight;
    r.least = cell_estimator_variance(cells, least_variance_guide(cells)) * weight;
    r.floor = guide_variance_floor(second_moments, means) * weight;
    r.field_alpha = alpha;
    out.push_back(r);
  }
  return bound;
}

}  // namespace pxf
