// Light sampling: emissive triangles (near-field choice, uniform in area or, on a near rectangle,
// in solid angle; quads kept stratified), the environment
// (luminance x sin(theta)) and the light types (by power) against their pdfs by chi-square, each
// with a separate selection number and with the selection taken from the point's u.x; punctual
// light falloffs.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "pathtracer/lights.h"
#include "pathtracer/rng.h"
#include "scene/texture.h"
#include "testing/shapes.h"
#include "testing/stat_tests.h"

namespace pxf {
namespace {

// Bonferroni over the thirteen chi-square tests here (6 near-field, 2 double-sided quad, 3
// environment, 2 light types).
constexpr double kAlpha = 0.01 / 13;

Scene three_emitters() {
  Scene scene;
  scene.materials = {make_diffuse(glm::vec3(0.5f)), make_emitter(glm::vec3(1.0f, 2.0f, 3.0f)),
                     make_emitter(glm::vec3(10.0f)), make_emitter(glm::vec3(0.5f, 0.1f, 0.1f))};
  scene.meshes.push_back(make_quad(glm::vec3(-5, 0, -5), glm::vec3(10, 0, 0), glm::vec3(0, 0, 10), 0));  // not a light
  scene.meshes.push_back(make_quad(glm::vec3(0, 2, 0), glm::vec3(1, 0, 0), glm::vec3(0, 0, 1), 1));
  scene.meshes.push_back(make_quad(glm::vec3(2, 3, 0), glm::vec3(0.2f, 0, 0), glm::vec3(0, 0.1f, 0.3f), 2));
  scene.meshes.push_back(make_box(glm::vec3(-2, 1, -2), glm::vec3(-1, 1.5f, -1.7f), 3));
  return scene;
}

// Which of the 4 midpoint-subdivision sub-triangles (equal areas) barycentrics (b1, b2) fall in.
int sub_triangle(glm::vec2 b) {
  float b0 = 1.0f - b.x - b.y;
  if (b0 > 0.5f) return 0;
  if (b.x > 0.5f) return 1;
  if (b.y > 0.5f) return 2;
  return 3;
}

// The selection probability of each emissive triangle seen from `from`, written out from the
// definition (LightSampler's near-field selection): per mesh 1/2 power share + 1/2 share of
// power / (d^2 + (half diagonal / 10)^2), d the distance to the mesh's box, both over the meshes
// that can light `from` (a one-sided flat mesh cannot light a point behind its plane); inside the
// mesh by power.
std::vector<double> expected_triangle_pmfs(const Scene& scene, const LightSampler& lights, glm::vec3 from) {
  std::vector<double> mesh_power(scene.meshes.size(), 0.0), near(scene.meshes.size(), 0.0);
  // A mesh is flat here when all its triangles share the first one's normal (the quads; not the box).
  std::vector<bool> flat(scene.meshes.size(), true), behind(scene.meshes.size(), false);
  std::vector<glm::vec3> first_normal(scene.meshes.size(), glm::vec3(0.0f));
  for (size_t i = 0; i < lights.emissive_triangle_count(); ++i) {
    const auto& t = lights.triangle(i);
    mesh_power[t.mesh] += t.area * luminance(t.material->emissive);
    if (t.prim == 0) first_normal[t.mesh] = t.normal;
    flat[t.mesh] = flat[t.mesh] && glm::dot(t.normal, first_normal[t.mesh]) > 0.9999f;
    behind[t.mesh] = glm::dot(from - t.p0, t.normal) <= 0.0f;
  }
  for (size_t m = 0; m < scene.meshes.size(); ++m)
    if (flat[m] && behind[m] && !scene.materials[scene.meshes[m].material].double_sided) mesh_power[m] = 0.0;
  double total = 0, near_total = 0;
  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    if (!(mesh_power[m] > 0)) continue;
    glm::vec3 lo(1e30f), hi(-1e30f);
    for (glm::vec3 p : scene.meshes[m].positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
    glm::dvec3 d(0.0);  // from `from` to the box
    for (int k = 0; k < 3; ++k) d[k] = std::max({0.0, double(lo[k]) - from[k], double(from[k]) - hi[k]});
    const double half_diagonal2 = 0.25 * glm::dot(glm::dvec3(hi - lo), glm::dvec3(hi - lo));
    near[m] = mesh_power[m] / (glm::dot(d, d) + 0.01 * half_diagonal2);
    total += mesh_power[m];
    near_total += near[m];
  }
  std::vector<double> pmf;
  for (size_t i = 0; i < lights.emissive_triangle_count(); ++i) {
    const auto& t = lights.triangle(i);
    const double p_mesh = 0.5 * mesh_power[t.mesh] / total + 0.5 * near[t.mesh] / near_total;
    pmf.push_back(mesh_power[t.mesh] > 0 ? p_mesh * t.area * luminance(t.material->emissive) / mesh_power[t.mesh] : 0.0);
  }
  return pmf;
}

// Expected counts of n light samples from `from` in each emissive triangle's 4 midpoint
// sub-triangles: the area density the sampler claims, pdf_triangle() x cos / r^2 (without the
// category's probability), integrated over each sub-triangle on a 32 x 32 grid of equal small
// triangles. Uniform in area it is pmf / 4 each; solid-angle sampling weights the nearer parts.
std::vector<double> expected_sub_triangle_counts(const LightSampler& lights, glm::vec3 from, int n) {
  const int grid = 32;
  std::vector<double> expected(lights.emissive_triangle_count() * 4, 0.0);
  for (size_t i = 0; i < lights.emissive_triangle_count(); ++i) {
    const auto& t = lights.triangle(i);
    for (int a = 0; a < grid; ++a)
      for (int b = 0; a + b < grid; ++b)
        for (int flip = 0; flip < 2 && a + b + flip < grid; ++flip) {
          // Small triangle (a, b) upright or flipped; its centroid in barycentrics.
          const glm::vec2 bary = flip ? glm::vec2(a + 2.0f / 3.0f, b + 2.0f / 3.0f) / float(grid)
                                      : glm::vec2(a + 1.0f / 3.0f, b + 1.0f / 3.0f) / float(grid);
          const glm::vec3 x = t.p0 + bary.x * t.e1 + bary.y * t.e2, d = x - from;
          const double r2 = glm::dot(d, d), cosine = std::abs(glm::dot(d, t.normal)) / std::sqrt(r2);
          const double density = lights.pdf_triangle(t.mesh, t.prim, from, x, t.normal) * cosine / r2 /
                                 lights.triangles_probability();
          expected[i * 4 + sub_triangle(bary)] += n * density * t.area / (grid * grid);
        }
  }
  return expected;
}

TEST(Lights, EmissiveTriangleSamplingFollowsNearFieldSelectionAndItsDensity) {
  Scene scene = three_emitters();
  LightSampler lights(scene);
  ASSERT_FALSE(lights.empty());
  ASSERT_TRUE(lights.near_field_selection());
  const size_t count = lights.emissive_triangle_count();
  ASSERT_EQ(count, 2u + 2u + 12u);
  const glm::vec3 below(0.3f, 0.01f, 0.2f);
  // From four places: the pmfs follow the definition and sum to 1; next to the small box its
  // triangles get far more than their power share; above the first quad (it faces down) it gets 0.
  const glm::vec3 above(0.5f, 2.5f, 0.5f);
  for (glm::vec3 at : {below, glm::vec3(-1.5f, 0.9f, -1.85f), glm::vec3(40.0f, 0.0f, 0.0f), above}) {
    const std::vector<double> want = expected_triangle_pmfs(scene, lights, at);
    double sum = 0;
    for (size_t i = 0; i < count; ++i) {
      EXPECT_NEAR(lights.triangle_selection_pmf(i, at), want[i], 1e-5 + 1e-4 * want[i]) << i;
      sum += lights.triangle_selection_pmf(i, at);
    }
    EXPECT_NEAR(sum, 1.0, 1e-5);
  }
  double box_near = 0, box_far = 0;
  for (size_t i = 4; i < count; ++i) {
    box_near += lights.triangle_selection_pmf(i, glm::vec3(-1.5f, 0.9f, -1.85f));
    box_far += lights.triangle_selection_pmf(i, glm::vec3(40.0f, 0.0f, 0.0f));
  }
  EXPECT_GT(box_near, 2.0 * box_far);
  EXPECT_EQ(lights.triangle_selection_pmf(0, above), 0.0f);
  EXPECT_EQ(lights.triangle_selection_pmf(1, above), 0.0f);
  EXPECT_GT(lights.triangle_selection_pmf(2, above), 0.0f);

  // Both ways of drawing: a separate selection number, and one 2D number whose first coordinate
  // selects and is reused, rescaled, for the point (what the Sobol sampler uses); below the quads,
  // above the first one, and just under it (close enough for solid-angle sampling of the quad).
  const glm::vec3 under(0.6f, 1.6f, 0.45f);
  ASSERT_TRUE(LightSampler::near_enough_for_solid_angle(lights.parallelogram(0), under));
  ASSERT_FALSE(LightSampler::near_enough_for_solid_angle(lights.parallelogram(0), below));
  for (glm::vec3 from : {below, above, under}) {
    for (bool shared : {false, true}) {
      SCOPED_TRACE(shared ? "selection from u.x" : "separate selection number");
      SCOPED_TRACE(from == above ? "above the first quad" : from == under ? "under the first quad" : "below the quads");
      const int n = 200000;
      std::vector<double> observed(count * 4, 0.0);
      const std::vector<double> expected = expected_sub_triangle_counts(lights, from, n);
      Rng rng(shared ? 10 : 9, 0, 0);
      int pdf_mismatches = 0;
      for (int k = 0; k < n; ++k) {
        float u_select = rng.next_float();
        glm::vec2 u = rng.next_2d();
        glm::vec3 point;
        glm::vec2 b;
        float area_pdf;
        size_t i = shared ? lights.sample_triangle_point(from, u, &point, &b, &area_pdf)
                          : lights.sample_triangle_point(from, u_select, u, &point, &b, &area_pdf);
        observed[i * 4 + sub_triangle(b)] += 1.0;
        // The full light sample's solid-angle pdf equals pdf_triangle() for the same point.
        LightSample ls;
        if (k % 50 == 0 && (shared ? lights.sample(from, u, &ls) : lights.sample(from, u_select, u, &ls))) {
          EXPECT_EQ(ls.point, point);
          const auto& tri = lights.triangle(i);
          float pdf = lights.pdf_triangle(tri.mesh, tri.prim, from, ls.point, tri.normal);
          if (std::abs(pdf - ls.pdf) > 1e-3f * pdf) ++pdf_mismatches;
        }
      }
      EXPECT_EQ(pdf_mismatches, 0);
      stat::ChiSquareResult r = stat::chi_square(observed, expected);
      EXPECT_TRUE(r.problem.empty()) << r.problem;
      EXPECT_GT(r.p_value, kAlpha) << "chi2 " << r.statistic << " dof " << r.dof;
    }
  }
}

TEST(Lights, DoubleSidedQuadIsSampledInSolidAngleFromEitherSide) {
  // A double-sided quad emitter seen from near on either side: solid-angle sampling (the point is
  // close), the sub-triangle counts against the density the sampler claims, and the light
  // sample's pdf equal to pdf_triangle().
  Scene scene;
  scene.materials = {make_emitter(glm::vec3(1.0f))};
  scene.materials[0].double_sided = true;
  scene.meshes.push_back(make_quad(glm::vec3(0, 2, 0), glm::vec3(1, 0, 0), glm::vec3(0, 0, 1), 0));
  LightSampler lights(scene);
  ASSERT_EQ(lights.emissive_triangle_count(), 2u);
  for (glm::vec3 from : {glm::vec3(0.3f, 1.5f, 0.6f), glm::vec3(0.8f, 2.4f, 0.2f)}) {
    ASSERT_TRUE(LightSampler::near_enough_for_solid_angle(lights.parallelogram(0), from));
    const int n = 100000;
    const std::vector<double> expected = expected_sub_triangle_counts(lights, from, n);
    std::vector<double> observed(expected.size(), 0.0);
    Rng rng(21, 0, 0);
    int pdf_mismatches = 0;
    for (int k = 0; k < n; ++k) {
      const glm::vec2 u = rng.next_2d();
      glm::vec3 point;
      glm::vec2 b;
      float area_pdf;
      const size_t i = lights.sample_triangle_point(from, u, &point, &b, &area_pdf);
      observed[i * 4 + sub_triangle(b)] += 1.0;
      LightSample ls;
      if (k % 50 == 0 && lights.sample(from, u, &ls)) {
        const auto& tri = lights.triangle(i);
        const float pdf = lights.pdf_triangle(tri.mesh, tri.prim, from, ls.point, tri.normal);
        if (std::abs(pdf - ls.pdf) > 1e-3f * pdf) ++pdf_mismatches;
      }
    }
    EXPECT_EQ(pdf_mismatches, 0);
    const stat::ChiSquareResult r = stat::chi_square(observed, expected);
    EXPECT_TRUE(r.problem.empty()) << r.problem;
    EXPECT_GT(r.p_value, kAlpha) << "chi2 " << r.statistic << " dof " << r.dof;
  }
}

TEST(Lights, SphericalRectangleSolidAngle) {
  // On the axis of a 2 x 1 rectangle at distance 0.7: 4 asin(ab / sqrt((a^2 + d^2)(b^2 + d^2))).
  SphericalRectangle sr;
  ASSERT_TRUE(sr.init(glm::vec3(0.0f), glm::vec3(-1.0f, -0.5f, 0.7f), glm::vec3(2, 0, 0), glm::vec3(0, 1, 0)));
  const double a = 1.0, b = 0.5, d = 0.7;
  EXPECT_NEAR(sr.solid_angle(), 4.0 * std::asin(a * b / std::sqrt((a * a + d * d) * (b * b + d * d))), 1e-5);
  // Off the axis, seen from behind its normal, edges in either order: the integral of cos / r^2.
  const glm::vec3 corner(0.3f, -0.2f, -1.0f), ex(1.5f, 0.0f, 0.0f), ey(0.0f, 0.8f, 0.0f);
  double integral = 0.0;
  const int steps = 400;
  for (int i = 0; i < steps; ++i)
    for (int j = 0; j < steps; ++j) {
      const glm::dvec3 x = glm::dvec3(corner) + (i + 0.5) / steps * glm::dvec3(ex) + (j + 0.5) / steps * glm::dvec3(ey);
      const double r2 = glm::dot(x, x);
      integral += std::abs(x.z) / std::sqrt(r2) / r2 * (1.5 * 0.8) / (steps * steps);
    }
  ASSERT_TRUE(sr.init(glm::vec3(0.0f), corner, ex, ey));
  EXPECT_NEAR(sr.solid_angle(), integral, 1e-5 * integral);
  ASSERT_TRUE(sr.init(glm::vec3(0.0f), corner + ex, ey, -ex));
  EXPECT_NEAR(sr.solid_angle(), integral, 1e-5 * integral);
  // Its samples lie on the rectangle.
  ASSERT_TRUE(sr.init(glm::vec3(0.0f), corner, ex, ey));
  for (glm::vec2 u : {glm::vec2(0.0f), glm::vec2(0.5f), glm::vec2(0.99f, 0.01f), glm::vec2(0x1.fffffep-1f)}) {
    const glm::vec3 p = sr.sample(u) - corner;
    EXPECT_NEAR(p.z, 0.0f, 1e-5f);
    EXPECT_GE(p.x, -1e-5f);
    EXPECT_LE(p.x, 1.5f + 1e-5f);
    EXPECT_GE(p.y, -1e-5f);
    EXPECT_LE(p.y, 0.8f + 1e-5f);
  }
  // Edge-on (the viewpoint in its plane): nothing to sample this way.
  EXPECT_FALSE(sr.init(glm::vec3(0.0f, 0.0f, -1.0f), corner, ex, ey));
}

TEST(Lights, SharedSelectionKeepsStrataOnAQuadEmitter) {
  // A quad is two triangles; from one 2D number the points go on the quad as an affine image of the
  // unit square (a parallelogram), so the 16 cell centres of a 4 x 4 grid land one in each cell
  // of the quad. Drawn per triangle (half of u.x each, warped by the square-to-triangle map) they
  // would not. A trapezoid is left to its triangles.
  const glm::vec3 corner(0.0f, 2.0f, 0.0f), edge_u(1.0f, 0.0f, 0.3f), edge_v(0.2f, 0.0f, 0.8f);
  Scene scene;
  scene.materials = {make_emitter(glm::vec3(1.0f))};
  scene.meshes.push_back(make_quad(corner, edge_u, edge_v, 0));
  LightSampler lights(scene);
  ASSERT_EQ(lights.emissive_triangle_count(), 2u);
  const glm::vec3 from(0.3f, 0.0f, 0.4f);
  // Coordinates in the quad's frame: p = corner + x edge_u + y edge_v.
  const glm::vec3 n = glm::cross(edge_u, edge_v);
  auto quad_coordinates = [&](glm::vec3 p) {
    const glm::vec3 r = p - corner;
    return glm::vec2(glm::dot(glm::cross(r, edge_v), n), glm::dot(glm::cross(edge_u, r), n)) / glm::dot(n, n);
  };
  std::vector<int> count(16, 0);
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) {
      glm::vec3 point;
      glm::vec2 b;
      float area_pdf;
      const size_t light = lights.sample_triangle_point(from, glm::vec2((i + 0.5f) / 4, (j + 0.5f) / 4), &point, &b, &area_pdf);
      // The triangle and barycentrics returned are those of the point.
      const auto& t = lights.triangle(light);
      EXPECT_LT(glm::length(t.p0 + b.x * t.e1 + b.y * t.e2 - point), 1e-5f);
      EXPECT_NEAR(area_pdf, 1.0f / glm::length(n), 1e-5f);
      const glm::vec2 q = quad_coordinates(point);
      ASSERT_TRUE(q.x >= 0.0f && q.x < 1.0f && q.y >= 0.0f && q.y < 1.0f) << q.x << " " << q.y;
      ++count[static_cast<int>(q.y * 4) * 4 + static_cast<int>(q.x * 4)];
    }
  for (int c = 0; c < 16; ++c) EXPECT_EQ(count[c], 1) << "cell " << c;

  EXPECT_GE(lights.triangle(0).parallelogram, 0);
  Mesh trapezoid = make_quad(corner, edge_u, edge_v, 0);
  trapezoid.positions[2] += 0.01f * edge_u;
  scene.meshes = {trapezoid};
  const LightSampler trapezoid_lights(scene);
  EXPECT_EQ(trapezoid_lights.triangle(0).parallelogram, -1);
  EXPECT_EQ(trapezoid_lights.triangle(1).parallelogram, -1);
}

Scene random_environment(int width, int height, uint64_t seed) {
  Scene scene;
  scene.materials = {make_diffuse(glm::vec3(0.5f))};
  Environment env;
  env.image.width = width;
  env.image.height = height;
  env.image.nearest = true;
  env.image.wrap_t = Wrap::ClampToEdge;
  Rng rng(seed, 0, 0);
  for (int i = 0; i < width * height; ++i) {
    float v = rng.next_float();
    v = v < 0.2f ? 0.0f : v * v * 10.0f;  // some black texels, a wide dynamic range
    env.image.texels.push_back(glm::vec4(v, 0.5f * v, 2.0f * v, 1.0f));
  }
  scene.environment = env;
  return scene;
}

// Environment directions drawn (directly, or through the whole light choice when `shared`) land
// in bu x bv bins of (u, v) as often as their claimed pdf integrates to (sub x sub points per bin:
// exact where the bins hold whole cells of the importance map), and the pdf a sample claims is the
// one environment_direction_pdf gives for its direction.
void expect_environment_sampling_matches_its_pdf(const Scene& scene, bool shared, int bu, int bv, int sub) {
  LightSampler lights(scene);
  ASSERT_TRUE(lights.has_environment());
  const int n = 300000;
  std::vector<double> observed(bu * bv, 0.0);
  Rng rng(4, 0, 0);
  int pdf_mismatches = 0, drawn = 0;
  for (int k = 0; k < n; ++k) {
    float pdf;
    glm::vec3 d;
    if (shared) {
      LightSample ls;
      if (!lights.sample(glm::vec3(0.0f), rng.next_2d(), &ls) || !std::isinf(ls.distance)) continue;
      d = ls.wi;
      pdf = ls.pdf / lights.environment_probability();
    } else {
      d = lights.sample_environment_direction(rng.next_2d(), &pdf);
    }
    glm::vec2 uv = equirect_uv(d);
    int x = std::min(bu - 1, static_cast<int>(uv.x * bu)), y = std::min(bv - 1, static_cast<int>(uv.y * bv));
    observed[y * bu + x] += 1.0;
    ++drawn;
    float again = lights.environment_direction_pdf(d);
    if (std::abs(again - pdf) > 2e-3f * pdf) ++pdf_mismatches;
  }
  if (shared) {
    EXPECT_GT(drawn, n / 4);
  }
  // Expected counts integrate pdf(direction) over each bin.
  std::vector<double> expected(bu * bv, 0.0);
  for (int y = 0; y < bv * sub; ++y) {
    for (int x = 0; x < bu * sub; ++x) {
      glm::vec2 uv((x + 0.5f) / (bu * sub), (y + 0.5f) / (bv * sub));
      glm::vec3 d = equirect_direction(uv);
      double jacobian = 2.0 * M_PI * M_PI * std::sin(M_PI * uv.y);  // dω = 2 pi^2 sin(theta) du dv
      expected[(y / sub) * bu + x / sub] +=
          drawn * lights.environment_direction_pdf(d) * jacobian / (double(bu * sub) * double(bv * sub));
    }
  }
  EXPECT_LE(pdf_mismatches, n / 10000);  // texel-boundary round-off only
  stat::ChiSquareResult r = stat::chi_square(observed, expected);
  EXPECT_TRUE(r.problem.empty()) << r.problem;
  EXPECT_GT(r.p_value, kAlpha) << "chi2 " << r.statistic << " dof " << r.dof;
}

TEST(Lights, EnvironmentSamplingMatchesItsPdf) {
  // Directly, and through the whole light choice from one 2D number (a quad emitter beside the
  // environment, so u.x must be rescaled into the environment's share before it picks the column).
  for (bool shared : {false, true}) {
    SCOPED_TRACE(shared ? "through sample(position, u)" : "sample_environment_direction");
    Scene scene = random_environment(16, 8, 21);
    if (shared) {
      scene.materials.push_back(make_emitter(glm::vec3(3.0f)));
      scene.meshes.push_back(make_quad(glm::vec3(0, 2, 0), glm::vec3(1, 0, 0), glm::vec3(0, 0, 1), 1));
    }
    expect_environment_sampling_matches_its_pdf(scene, shared, 48, 24, 6);  // bins finer than the texels
  }
}

// A smooth sky, wider than LightSampler::kEnvironmentImportanceWidth and not a multiple of the
// block in either direction, with a black band and, optionally, a sun of 2 x 2 texels.
Scene smooth_sky(bool with_sun) {
  Scene scene;
  scene.materials = {make_diffuse(glm::vec3(0.5f))};
  Environment env;
  env.image.width = 1030;
  env.image.height = 517;
  env.image.wrap_t = Wrap::ClampToEdge;
  for (int y = 0; y < env.image.height; ++y)
    for (int x = 0; x < env.image.width; ++x) {
      float v = 1.0f + 0.5f * std::sin(6.2831853f * x / env.image.width) + 2.0f * y / env.image.height;
      if (y >= 300 && y < 340) v = 0.0f;  // the black band: its edges cut blocks
      if (with_sun && x >= 600 && x < 602 && y >= 100 && y < 102) v = 1.0e5f;
      env.image.texels.push_back(glm::vec4(v, 0.8f * v, 0.6f * v, 1.0f));
    }
  scene.environment = env;
  return scene;
}

// The pdf over (u, v) at texel (x, y)'s centre.
float texel_pdf_uv(const LightSampler& lights, const Texture& image, int x, int y) {
  const glm::vec2 uv((x + 0.5f) / image.width, (y + 0.5f) / image.height);
  return lights.environment_direction_pdf(equirect_direction(uv)) * 2.0f * kPi * kPi * std::sin(kPi * uv.y);
}

TEST(Lights, EnvironmentImportanceMapIsCoarseOnlyWhereThatCostsLittleVariance) {
  {
    SCOPED_TRACE("smooth sky: blocks of 5 x 5 texels, uniform inside");
    const Scene scene = smooth_sky(false);
    const LightSampler lights(scene);
    const Texture& image = scene.environment->image;
    // Texels 0-4 of row 0-4 share a block (1030 / 256 rounds up to 5); texel 5 starts the next.
    const float first = texel_pdf_uv(lights, image, 0, 2);
    EXPECT_NEAR(texel_pdf_uv(lights, image, 4, 2), first, 1e-3f * first);
    EXPECT_NEAR(texel_pdf_uv(lights, image, 2, 0), first, 1e-3f * first);
    EXPECT_NE(texel_pdf_uv(lights, image, 5, 2), first);
    // Every texel with light keeps a positive pdf, and black blocks none.
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; x += 7) {
        const bool lit = image.texels[static_cast<size_t>(y) * image.width + x].x > 0.0f;
        if (lit) {
          ASSERT_GT(texel_pdf_uv(lights, image, x, y), 0.0f) << x << ", " << y;
        }
        if (y >= 305 && y < 335) {
          ASSERT_EQ(texel_pdf_uv(lights, image, x, y), 0.0f) << x << ", " << y;
        }
      }
    expect_environment_sampling_matches_its_pdf(scene, false, 103, 52, 4);  // bins of 2 x 2 cells (206 x 104)
  }
  {
    SCOPED_TRACE("the same sky with a sun of 2 x 2 texels: one cell per texel");
    const Scene scene = smooth_sky(true);
    const LightSampler lights(scene);
    const Texture& image = scene.environment->image;
    // The sun's texels against the sky texel beside them in the same block: the full map's
    // ratio of weights (1e5 against about 1.4), where a block sum would give 1.
    EXPECT_GT(texel_pdf_uv(lights, image, 600, 100) / texel_pdf_uv(lights, image, 603, 100), 1.0e4f);
  }
}

// A point light (I = 3) and a spot (I = 5, cone 0.2 to 0.4 around straight down) at (0, 3, 0), and
// a sun (E = 1.5) from (0, 0.6, 0.8), white.
struct PointSpotSun {
  PunctualLight point, spot, sun;
};
PointSpotSun point_spot_and_sun() {
  PointSpotSun l;
  l.point.intensity = 3.0f;
  l.point.position = l.spot.position = glm::vec3(0, 3, 0);
  l.spot.direction = glm::vec3(0, -1, 0);
  l.spot.type = PunctualLight::Type::Spot;
  l.spot.intensity = 5.0f;
  l.spot.inner_cone = 0.2f;
  l.spot.outer_cone = 0.4f;
  l.sun.type = PunctualLight::Type::Directional;
  l.sun.intensity = 1.5f;
  l.sun.direction = glm::vec3(0.0f, -0.6f, -0.8f);
  return l;
}

TEST(Lights, LightTypesAreSelectedByPower) {
  // A one-sided emitter quad (L = 2, area 0.5), a uniform sky (L = 0.25), a point light (I = 3), a
  // spot (I = 5, mean cone angle 0.3), a sun (E = 1.5) and two dim points (I = 1), white: more
  // punctual lights than kMaxFixedLights, so all of them are chosen by sampling. The geometry spans
  // a 4 x 2 x 4 box: r = sqrt(36) / 2 = 3. Expected powers: quad pi x 2 x 0.5; sky pi r^2 x 4 pi x
  // 0.25; punctual 4 pi x 3 + 2 pi (1 - cos 0.3) x 5 + pi r^2 x 1.5 + 2 x 4 pi.
  Scene scene;
  scene.materials = {make_diffuse(glm::vec3(0.5f)), make_emitter(glm::vec3(2.0f))};
  scene.meshes.push_back(make_quad(glm::vec3(-2, 0, -2), glm::vec3(4, 0, 0), glm::vec3(0, 0, 4), 0));
  scene.meshes.push_back(make_quad(glm::vec3(0, 2, 0), glm::vec3(1, 0, 0), glm::vec3(0, 0, 0.5f), 1));
  Environment env;
  env.image.width = 64;
  env.image.height = 32;
  env.image.texels.assign(64 * 32, glm::vec4(0.25f, 0.25f, 0.25f, 1.0f));
  scene.environment = env;
  const auto [point, spot, sun] = point_spot_and_sun();
  PunctualLight dim = point;
  dim.intensity = 1.0f;
  scene.lights = {point, spot, sun, dim, dim};
  LightSampler lights(scene);
  ASSERT_EQ(lights.fixed_light_count(), 0u);
  const double r2 = 9.0;
  const double tri = kPi * 2.0 * 0.5, sky = kPi * r2 * 4 * kPi * 0.25;
  const double punctual = 4 * kPi * 3.0 + 2 * kPi * (1 - std::cos(0.3)) * 5.0 + kPi * r2 * 1.5 + 2 * 4 * kPi;
  const double total = tri + sky + punctual;
  EXPECT_NEAR(lights.triangles_probability(), tri / total, 1e-3 * tri / total);
  EXPECT_NEAR(lights.environment_probability(), sky / total, 1e-3 * sky / total);
  EXPECT_NEAR(lights.punctual_probability(), punctual / total, 1e-3 * punctual / total);
  // The pdfs of the samples carry the selection: the punctual lights share their category evenly.
  LightSample ls;
  ASSERT_TRUE(lights.sample(glm::vec3(0.5f, 1.0f, 0.25f), 0.9999f, glm::vec2(0.5f), &ls));
  EXPECT_TRUE(ls.delta);
  EXPECT_NEAR(ls.pdf, lights.punctual_probability() / 5.0f, 1e-6f);
  float env_pdf;
  lights.sample_environment_direction(glm::vec2(0.3f, 0.6f), &env_pdf);
  EXPECT_NEAR(lights.pdf_environment(glm::vec3(0, 0, -1)), lights.environment_probability() / (4 * kPi), 1e-3f);
  // Frequencies of the selected category over many draws, from a point every light reaches: chi-square against the probabilities.
  // With a separate selection number and with the selection taken from u.x.
  for (bool shared : {false, true}) {
    const int n = 100000;
    std::vector<double> observed(3, 0.0);
    Rng rng(shared ? 18 : 17, 0, 0);
    const glm::vec3 at(0.5f, 1.0f, 0.25f);
    for (int k = 0; k < n; ++k) {
      const float u_select = rng.next_float();
      const glm::vec2 u = rng.next_2d();
      if (!(shared ? lights.sample(at, u, &ls) : lights.sample(at, u_select, u, &ls))) continue;
      observed[ls.delta ? 2 : std::isinf(ls.distance) ? 1 : 0] += 1.0;
    }
    const std::vector<double> expected = {n * tri / total, n * sky / total, n * punctual / total};
    stat::ChiSquareResult r = stat::chi_square(observed, expected);
    EXPECT_GT(r.p_value, kAlpha) << (shared ? "shared: " : "") << "chi2 " << r.statistic << " dof " << r.dof;
  }
}

TEST(Lights, FewPunctualLightsAreTakenAtEveryVertex) {
  // A point light (I = 3), a spot (I = 5, cone 0.2 to 0.4 around straight down) and a sun (E = 1.5):
  // no more than kMaxFixedLights, so each is taken at every vertex (pdf 1), outside the category
  // choice, and its sample is exact: the same from the same point.
  Scene scene;
  scene.materials = {make_diffuse(glm::vec3(0.5f))};
  scene.meshes.push_back(make_quad(glm::vec3(-2, 0, -2), glm::vec3(4, 0, 0), glm::vec3(0, 0, 4), 0));
  auto [point, spot, sun] = point_spot_and_sun();
  sun.color = glm::vec3(1.0f, 0.8f, 0.5f);
  scene.lights = {point, spot, sun};
  const LightSampler lights(scene);
  ASSERT_EQ(lights.fixed_light_count(), 3u);
  EXPECT_EQ(lights.punctual_probability(), 0.0f);
  EXPECT_EQ(lights.triangles_probability(), 0.0f);
  EXPECT_FALSE(lights.empty());
  const glm::vec3 below(0.0f, 1.0f, 0.0f), aside(1.9f, 0.0f, 0.0f);  // 2 below the lights; off the spot's cone
  LightSample ls;
  ASSERT_TRUE(lights.fixed_light_sample(0, below, &ls));  // the point: I / d^2
  EXPECT_TRUE(ls.delta);
  EXPECT_EQ(ls.pdf, 1.0f);
  EXPECT_NEAR(ls.distance, 2.0f, 1e-6f);
  EXPECT_NEAR(glm::length(ls.radiance - glm::vec3(0.75f)), 0.0f, 1e-6f);
  ASSERT_TRUE(lights.fixed_light_sample(1, below, &ls));  // the spot, inside its inner cone
  EXPECT_NEAR(glm::length(ls.radiance - glm::vec3(1.25f)), 0.0f, 1e-6f);
  EXPECT_FALSE(lights.fixed_light_sample(1, aside, &ls));  // outside its cone: no light
  ASSERT_TRUE(lights.fixed_light_sample(2, aside, &ls));   // the sun: towards where its light comes from, E x colour
  EXPECT_EQ(ls.pdf, 1.0f);
  EXPECT_TRUE(std::isinf(ls.distance));
  EXPECT_NEAR(glm::length(ls.wi - glm::vec3(0.0f, 0.6f, 0.8f)), 0.0f, 1e-6f);
  EXPECT_NEAR(glm::length(ls.radiance - glm::vec3(1.5f, 1.2f, 0.75f)), 0.0f, 1e-6f);
}

TEST(Lights, PunctualLightsBeyondTheLimitAreChosenBySampling) {
  // kMaxFixedLights suns are each sampled at every vertex; one more and they all join the punctual
  // category, chosen by power (pi r^2 E each; r = 3 for the 4 x 2 x 4 box) against the sky.
  Scene scene;
  scene.materials = {make_diffuse(glm::vec3(0.5f))};
  scene.meshes.push_back(make_quad(glm::vec3(-2, 0, -2), glm::vec3(4, 0, 0), glm::vec3(0, 0, 4), 0));
  scene.meshes.push_back(make_quad(glm::vec3(-2, 2, -2), glm::vec3(4, 0, 0), glm::vec3(0, 0, 4), 0));
  Environment env;
  env.image.width = 64;
  env.image.height = 32;
  env.image.texels.assign(64 * 32, glm::vec4(0.25f, 0.25f, 0.25f, 1.0f));
  scene.environment = env;
  PunctualLight sun;
  sun.type = PunctualLight::Type::Directional;
  sun.intensity = 0.5f;
  for (size_t k = 0; k < LightSampler::kMaxFixedLights; ++k) scene.lights.push_back(sun);
  {
    const LightSampler lights(scene);
    EXPECT_EQ(lights.fixed_light_count(), LightSampler::kMaxFixedLights);
    EXPECT_EQ(lights.punctual_probability(), 0.0f);
    EXPECT_EQ(lights.environment_probability(), 1.0f);
  }
  scene.lights.push_back(sun);
  const LightSampler lights(scene);
  EXPECT_EQ(lights.fixed_light_count(), 0u);
  const double suns = 5 * kPi * 9.0 * 0.5, sky = LightSampler::environment_power(env, 3.0f);
  EXPECT_NEAR(lights.punctual_probability(), suns / (suns + sky), 1e-6);
  LightSample ls;
  ASSERT_TRUE(lights.sample(glm::vec3(0.0f, 1.0f, 0.0f), 0.9999f, glm::vec2(0.5f), &ls));
  EXPECT_TRUE(ls.delta);
  EXPECT_NEAR(ls.pdf, lights.punctual_probability() / 5.0f, 1e-6f);
}

TEST(Lights, TexturedEmitterSampleCarriesTheTexelUnderItsPoint) {
  // A quad emitter with a 2 x 2 nearest-filtered emissive texture (a different colour per quarter)
  // and a plain one: every light sample's radiance is the texel under its point (uv0 of make_quad:
  // u along edge_u, v = 1 - t along edge_v), from near (solid angle) and from far (area), with
  // both selections; the plain emitter's is its factor.
  Scene scene;
  Texture glow;
  glow.width = glow.height = 2;
  glow.nearest = true;
  glow.texels = {glm::vec4(1, 0, 0, 1), glm::vec4(0, 1, 0, 1), glm::vec4(0, 0, 1, 1), glm::vec4(1, 1, 0, 1)};
  scene.textures = {glow};
  Material textured = make_emitter(glm::vec3(2.0f));
  textured.emissive_texture.texture = 0;
  scene.materials = {textured, make_emitter(glm::vec3(0.5f, 0.25f, 0.125f))};
  const glm::vec3 corner(0, 2, 0), edge_u(1, 0, 0), edge_v(0, 0, 1);
  scene.meshes.push_back(make_quad(corner, edge_u, edge_v, 0));
  scene.meshes.push_back(make_quad(glm::vec3(5, 2, 5), edge_u, edge_v, 1));
  const LightSampler lights(scene);
  Rng rng(31, 0, 0);
  int textured_samples = 0, plain_samples = 0;
  for (glm::vec3 from : {glm::vec3(0.4f, 1.6f, 0.3f), glm::vec3(0.5f, -6.0f, 0.5f)})
    for (bool shared : {false, true})
      for (int k = 0; k < 4000; ++k) {
        const float u_select = rng.next_float();
        const glm::vec2 u = rng.next_2d();
        LightSample ls;
        if (!(shared ? lights.sample(from, u, &ls) : lights.sample(from, u_select, u, &ls))) continue;
        if (ls.point.x > 2.0f) {
          ++plain_samples;
          ASSERT_EQ(ls.radiance, glm::vec3(0.5f, 0.25f, 0.125f));
          continue;
        }
        ++textured_samples;
        const glm::vec2 uv(glm::dot(ls.point - corner, edge_u), 1.0f - glm::dot(ls.point - corner, edge_v));
        const float margin = std::min({uv.x, 1.0f - uv.x, uv.y, 1.0f - uv.y, std::abs(uv.x - 0.5f), std::abs(uv.y - 0.5f)});
        if (margin < 1e-4f) continue;  // on a texel edge: either texel is right within float error
        const glm::vec4 texel = glow.texels[(uv.y < 0.5f ? 0 : 2) + (uv.x < 0.5f ? 0 : 1)];
        ASSERT_EQ(ls.radiance, 2.0f * glm::vec3(texel)) << "uv " << uv.x << " " << uv.y;
      }
  EXPECT_GT(textured_samples, 1000);
  EXPECT_GT(plain_samples, 100);
}

TEST(Lights, EquirectRoundTrip) {
  for (glm::vec3 d : {glm::vec3(0, 0, -1), glm::vec3(1, 0, 0), glm::normalize(glm::vec3(0.3f, 0.8f, 0.5f))}) {
    glm::vec3 back = equirect_direction(equirect_uv(d));
    EXPECT_NEAR(glm::length(back - d), 0.0f, 1e-5f);
  }
  EXPECT_NEAR(equirect_uv(glm::vec3(0, 0, -1)).x, 0.5f, 1e-6f);  // -z is the image center
  EXPECT_NEAR(equirect_uv(glm::vec3(0, 1, 0)).y, 0.0f, 1e-6f);   // up is the top row
}

TEST(Lights, PunctualFalloffs) {
  Scene scene;
  PunctualLight spot;
  spot.type = PunctualLight::Type::Spot;
  spot.position = glm::vec3(0, 2, 0);
  spot.direction = glm::vec3(0, -1, 0);
  spot.intensity = 8.0f;
  spot.inner_cone = 0.2f;
  spot.outer_cone = 0.4f;
  scene.lights.push_back(spot);
  LightSampler lights(scene);
  LightSample ls;
  ASSERT_TRUE(lights.fixed_light_sample(0, glm::vec3(0, 0, 0), &ls));
  EXPECT_TRUE(ls.delta);
  EXPECT_NEAR(ls.radiance.x, 8.0f / 4.0f, 1e-5f);  // inside the inner cone: I / d^2
  EXPECT_NEAR(ls.distance, 2.0f, 1e-6f);
  float inside_outer = std::tan(0.3f) * 2.0f;    // between the cones: partial
  EXPECT_TRUE(lights.fixed_light_sample(0, glm::vec3(inside_outer, 0, 0), &ls));
  EXPECT_GT(ls.radiance.x, 0.0f);
  EXPECT_LT(ls.radiance.x, 8.0f / (4.0f + inside_outer * inside_outer));
  EXPECT_FALSE(lights.fixed_light_sample(0, glm::vec3(std::tan(0.5f) * 2.0f, 0, 0), &ls));  // outside
}

// Path guiding's training photons (sample_emission): on average a photon carries the lights' total
// power (per channel: pi L area for each one-sided emitter, pi r^2 E for a sun through the scene's
// cross-section, 4 pi I for a point light), emitters send them to their lit side with cosine
// directions from points on them, and a sun's photons cross the scene's bounding sphere.
TEST(Lights, EmissionPhotonsCarryTheLightsPower) {
  Scene scene;
  scene.materials = {make_diffuse(glm::vec3(0.5f)), make_emitter(glm::vec3(1.0f, 2.0f, 3.0f)), make_emitter(glm::vec3(10.0f))};
  scene.meshes.push_back(make_quad(glm::vec3(-5, 0, -5), glm::vec3(10, 0, 0), glm::vec3(0, 0, 10), 0));
  scene.meshes.push_back(make_quad(glm::vec3(0, 2, 0), glm::vec3(1, 0, 0), glm::vec3(0, 0, 1), 1));  // faces -y
  scene.meshes.push_back(make_quad(glm::vec3(2, 3, 0), glm::vec3(0.5f, 0, 0), glm::vec3(0, 0, 0.5f), 2));
  PunctualLight sun;
  sun.type = PunctualLight::Type::Directional;
  sun.color = glm::vec3(1.0f, 0.9f, 0.8f);
  sun.intensity = 3.0f;
  sun.direction = glm::normalize(glm::vec3(0.3f, -1.0f, 0.2f));
  PunctualLight point;
  point.position = glm::vec3(0, 1, 0);
  point.color = glm::vec3(0.2f, 0.4f, 0.6f);
  point.intensity = 5.0f;
  scene.lights = {sun, point};
  const LightSampler lights(scene);
  const float radius = 0.5f * glm::length(glm::vec3(10, 3, 10));  // the scene's box: (-5,0,-5)..(5,3,5)
  const glm::vec3 center(0.0f, 1.5f, 0.0f);
  const glm::dvec3 expected = glm::dvec3(scene.materials[1].emissive) * (kPi * 1.0) +
                              glm::dvec3(scene.materials[2].emissive) * (kPi * 0.25) +
                              glm::dvec3(sun.color * sun.intensity) * (kPi * double(radius) * double(radius)) +
                              glm::dvec3(point.color * point.intensity) * (4.0 * kPi);
  const int n = 400000;
  Rng rng(17);
  glm::dvec3 sum(0.0), sum2(0.0);
  double quad_cos = 0.0;
  int quad_photons = 0;
  for (int i = 0; i < n; ++i) {
    EmittedPhoton photon;
    ASSERT_TRUE(lights.sample_emission(rng.next_2d(), rng.next_2d(), rng.next_2d(), &photon));
    ASSERT_NEAR(glm::length(photon.direction), 1.0f, 1e-5f);
    sum += glm::dvec3(photon.flux);
    sum2 += glm::dvec3(photon.flux) * glm::dvec3(photon.flux);
    if (std::abs(photon.origin.y - 2.0f) < 1e-3f) {  // the quad under y = 2 (its offset is tiny)
      EXPECT_TRUE(photon.origin.x >= 0.0f && photon.origin.x <= 1.0f && photon.origin.z >= 0.0f && photon.origin.z <= 1.0f);
      EXPECT_LT(photon.direction.y, 0.0f);
      quad_cos += -photon.direction.y;
      ++quad_photons;
    } else if (glm::length(photon.direction - sun.direction) < 1e-5f) {  // the sun's: aimed through the scene
      const glm::vec3 to_center = center - photon.origin;
      const float miss = glm::length(to_center - glm::dot(to_center, photon.direction) * photon.direction);
      EXPECT_LE(miss, radius * 1.0001f);
    }
  }
  for (int c = 0; c < 3; ++c) {
    const double mean = sum[c] / n, se = std::sqrt((sum2[c] / n - mean * mean) / n);
    EXPECT_NEAR(mean, expected[c], 4.0 * se + 1e-4 * expected[c]) << "channel " << c;
  }
  ASSERT_GT(quad_photons, 1000);
  EXPECT_NEAR(quad_cos / quad_photons, 2.0 / 3.0, 0.01);  // cosine-distributed: E[cos] = 2/3
  EmittedPhoton none;
  EXPECT_FALSE(LightSampler(Scene{}).sample_emission(glm::vec2(0.5f), glm::vec2(0.5f), glm::vec2(0.5f), &none));
}

}  // namespace
}  // namespace pxf
