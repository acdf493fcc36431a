// The solved sphere caustics (pathtracer/caustics/sphere_caustics.h): the fit, the solver's
// paths, and the sampling against its pdf (chi-square).
#include "pathtracer/caustics/sphere_caustics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "pathtracer/rng.h"
#include "testing/shapes.h"
#include "testing/stat_tests.h"

namespace pxf {
namespace {

constexpr double kPi = 3.14159265358979323846;

SphereCaster glass_caster() {
  SphereCaster c;
  c.center = glm::dvec3(0.0, 0.4, 0.0);
  c.radius = 0.4;
  c.ior = 1.5;
  return c;
}

SphereCaster mirror_caster() {
  SphereCaster c = glass_caster();
  c.mirror = true;
  return c;
}

// A quad light 1.6 above the sphere's centre, as two triangles.
SphereCausticSampler ceiling_light() {
  const glm::dvec3 p0(-0.3, 2.0, -0.2), u(0.6, 0.0, 0.0), v(0.0, 0.0, 0.4);
  std::vector<SphereCausticSampler::Emitter> emitters = {{p0, u, v, 0.12}, {p0 + u + v, -u, -v, 0.12}};
  return SphereCausticSampler(emitters, {1.0f, 1.0f});
}

TEST(SphereCaustics, FitsASphereMeshAndNothingElse) {
  const Mesh sphere = make_sphere(glm::vec3(0.2f, -0.6f, 0.3f), 0.4f, 0, 64, 32);
  SphereCaster c;
  ASSERT_TRUE(fit_sphere_caster(sphere.positions, sphere.normals, &c));
  EXPECT_NEAR(c.center.x, 0.2, 1e-6);
  EXPECT_NEAR(c.center.y, -0.6, 1e-6);
  EXPECT_NEAR(c.center.z, 0.3, 1e-6);
  EXPECT_NEAR(c.radius, 0.4, 1e-6);
  const Mesh box = make_box(glm::vec3(0.0f), glm::vec3(1.0f), 0);  // its corners lie on a sphere
  EXPECT_FALSE(fit_sphere_caster(box.positions, box.normals, &c));
  std::vector<glm::vec3> squashed = sphere.positions;
  for (glm::vec3& p : squashed) p.y *= 0.9f;  // an ellipsoid
  EXPECT_FALSE(fit_sphere_caster(squashed, sphere.normals, &c));
  EXPECT_FALSE(fit_sphere_caster(sphere.positions, {}, &c));  // no normals: faceted
}

// Every direction the solver returns reaches y, and a direction whose path reaches y is found.
TEST(SphereCaustics, SolverFindsThePathsThroughThePoint) {
  for (const SphereCaster& c : {glass_caster(), mirror_caster()}) {
    Rng rng(7, 1, 0);
    int tried = 0, found = 0, solutions = 0;
    double worst_miss = 0.0;
    for (int i = 0; i < 3000; ++i) {
      const glm::dvec3 x = c.center + glm::dvec3(2.0 * rng.next_float() - 1.0, -0.4 + 0.3 * rng.next_float(),
                                                 2.0 * rng.next_float() - 1.0);
      const glm::dvec3 offset(2.0 * rng.next_float() - 1.0, 2.0 * rng.next_float() - 1.0, 2.0 * rng.next_float() - 1.0);
      if (glm::length(offset) > 1.0) continue;
      const glm::dvec3 aim = c.center + c.radius * 0.9 * offset;  // within the rim the solver serves
      const glm::dvec3 w = glm::normalize(aim - x);
      glm::dvec3 o, d;
      if (glm::length(x - c.center) <= c.radius || !trace_sphere_caster(c, x, w, &o, &d)) continue;
      const glm::dvec3 y = o + (0.5 + 2.0 * rng.next_float()) * d;
      if (glm::length(y - c.center) <= c.radius * 1.01) continue;
      ++tried;
      glm::dvec3 paths[kMaxSphereCasterPaths];
      const int count = solve_sphere_caster(c, x, y, paths);
      bool has_w = false;
      for (int k = 0; k < count; ++k) {
        has_w |= glm::length(paths[k] - w) < 1e-6;
        glm::dvec3 ok, dk;
        ASSERT_TRUE(trace_sphere_caster(c, x, paths[k], &ok, &dk));
        const glm::dvec3 to = y - ok;
        worst_miss = std::max(worst_miss, glm::length(to - glm::dot(to, dk) * dk));
        ++solutions;
      }
      found += has_w;
    }
    std::printf("%s: %d of %d paths found again, %d solutions, worst miss %.2e\n", c.mirror ? "mirror" : "glass",
                found, tried, solutions, worst_miss);
    EXPECT_GT(tried, 1000);
    EXPECT_GE(found, 0.97 * tried);
    EXPECT_LT(worst_miss, 1e-9);
  }
}

// sample()'s directions are distributed as pdf() says: a chi-square test over the cone that holds
// the sphere, from a floor point beside a glass ball (in its caustic) and a point off a mirror ball.
TEST(SphereCaustics, SamplingMatchesItsPdf) {
  const SphereCausticSampler light = ceiling_light();
  struct Case {
    SphereCaster caster;
    glm::vec3 x;
  };
  for (const Case& test : {Case{glass_caster(), glm::vec3(0.12f, 0.0f, 0.08f)},
                           Case{mirror_caster(), glm::vec3(0.9f, 0.1f, 0.4f)}}) {
    const SphereCaster& c = test.caster;
    const glm::dvec3 to_center = c.center - glm::dvec3(test.x);
    const double distance = glm::length(to_center);
    const glm::dvec3 axis = to_center / distance;
    const double cos_max = std::sqrt(1.0 - c.radius * c.radius / (distance * distance));
    const glm::dvec3 helper = std::abs(axis.x) < 0.6 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
    const glm::dvec3 t1 = glm::normalize(glm::cross(axis, helper)), t2 = glm::cross(axis, t1);
    constexpr int kRows = 12, kColumns = 12, kSamples = 60000, kStrata = 48;
    const int failure_bin = kRows * kColumns;
    // A direction's bin: rows even in cos theta about the axis, columns even in phi.
    const auto bin_of = [&](const glm::dvec3& w) {
      const double cos_theta = glm::dot(w, axis);
      if (cos_theta < cos_max) return -1;
      const int row = std::min(kRows - 1, static_cast<int>((1.0 - cos_theta) / (1.0 - cos_max) * kRows));
      double phi = std::atan2(glm::dot(w, t2), glm::dot(w, t1));
      if (phi < 0.0) phi += 2.0 * kPi;
      const int column = std::min(kColumns - 1, static_cast<int>(phi / (2.0 * kPi) * kColumns));
      return row * kColumns + column;
    };
    std::vector<double> observed(failure_bin + 1, 0.0), expected(failure_bin + 1, 0.0);
    Rng rng(11, 3, 0);
    for (int i = 0; i < kSamples; ++i) {
      glm::vec3 w;
      const float u0 = rng.next_float(), u1 = rng.next_float(), u2 = rng.next_float();
      float pdf;
      if (!light.sample(c, test.x, u0, glm::vec2(u1, u2), &w, &pdf)) {
        observed[failure_bin] += 1.0;
        continue;
      }
      const float evaluated = light.pdf(c, test.x, w);  // sample() did not solve again: the same density
      EXPECT_NEAR(pdf, evaluated, 1e-3f * evaluated);
      const int bin = bin_of(glm::dvec3(w));
      ASSERT_GE(bin, 0) << "a solved direction outside the sphere's cone";
      observed[bin] += 1.0;
    }
    // Each bin's probability: the pdf integrated over it by jittered strata.
    const double bin_solid_angle = 2.0 * kPi * (1.0 - cos_max) / (kRows * kColumns);
    double total = 0.0;
    for (int row = 0; row < kRows; ++row)
      for (int column = 0; column < kColumns; ++column) {
        // The mean of the pdf over the bin by `strata` x `strata` jittered points (fine: the
        // light's image has sharp edges).
        const auto bin_mean = [&](int strata) {
          double sum = 0.0;
          for (int a = 0; a < strata; ++a)
            for (int b = 0; b < strata; ++b) {
              const double v = (row + (a + rng.next_float()) / strata) / kRows;
              const double phi = 2.0 * kPi * (column + (b + rng.next_float()) / strata) / kColumns;
              const double cos_theta = 1.0 - v * (1.0 - cos_max);
              const double sin_theta = std::sqrt(std::max(0.0, 1.0 - cos_theta * cos_theta));
              const glm::dvec3 w = cos_theta * axis + sin_theta * (std::cos(phi) * t1 + std::sin(phi) * t2);
              sum += light.pdf(c, test.x, glm::vec3(w));
            }
          return sum / (strata * strata);
        };
        const double probability = bin_mean(kStrata) * bin_solid_angle;
        expected[row * kColumns + column] = probability * kSamples;
        total += probability;
      }
    expected[failure_bin] = std::max(0.0, 1.0 - total) * kSamples;
    const stat::ChiSquareResult r = stat::chi_square(observed, expected);
    std::printf("%s at (%.2f %.2f %.2f): solved %.3f of the samples, pdf integrates to %.3f; chi2 %.1f, dof %d, p %.3g %s\n",
                c.mirror ? "mirror" : "glass", test.x.x, test.x.y, test.x.z, 1.0 - observed[failure_bin] / kSamples,
                total, r.statistic, r.dof, r.p_value, r.problem.c_str());
    EXPECT_GT(total, 0.05);
    EXPECT_GT(r.p_value, 1e-3) << r.problem;
  }
}

}  // namespace
}  // namespace pxf
