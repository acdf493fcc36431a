// The specular chains' sampler (pathtracer/caustics/specular_chain_sampler.h): which targets a plan
// aims at, and that the density pdf() gives is the one sample() draws with.
#include "pathtracer/caustics/specular_chain_sampler.h"

#include <gtest/gtest.h>

#include <cmath>

#include "pathtracer/rng.h"
#include "pathtracer/shading.h"
#include "testing/shapes.h"

namespace pxf {
namespace {

constexpr double kPi = 3.14159265358979323846;

// The scene and everything the sampler keeps references to.
struct Chains {
  explicit Chains(Scene s) : scene(std::move(s)), geometry(scene), lights(scene), materials(scene),
                             sampler(geometry, lights, materials) {}
  Scene scene;
  EmbreeScene geometry;
  LightSampler lights;
  BsdfMaterials materials;
  SpecularChainSampler sampler;
};

// The Cornell box with its mirror and glass spheres, optionally also lit by a uniform sky (then the
// solved chains share the spheres' draws with their cones).
Scene cornell(bool with_environment) {
  Scene scene = make_cornell_box(true);
  if (with_environment) scene.environment = uniform_environment(1.0f);
  return scene;
}

TraceParams with(bool specular_sampling, bool specular_chains) {
  TraceParams params;
  params.specular_sampling = specular_sampling;
  params.specular_chains = specular_chains;
  return params;
}

// Points inside the box, on a grid.
std::vector<glm::vec3> points_in_the_box() {
  std::vector<glm::vec3> points;
  for (float x = -0.9f; x <= 0.9f; x += 0.3f)
    for (float y = -0.95f; y <= 0.9f; y += 0.35f)
      for (float z = -0.9f; z <= 0.9f; z += 0.3f) points.emplace_back(x, y, z);
  return points;
}

int included(const SpecularChainSampler& chains, const SpecularChainSampler::Plan& plan, glm::vec3 p) {
  int n = 0;
  for (const SpecularChainSampler::Target& t : chains.targets()) n += plan.includes(t, p);
  return n;
}

TEST(SpecularChainSampler, NoPerfectlySpecularMeshNoChains) {
  const Chains c(make_cornell_box(false));
  EXPECT_TRUE(c.sampler.empty());
  EXPECT_FALSE(c.sampler.has_perfect_specular());
  for (bool all : {false, true})
    EXPECT_FALSE(c.sampler.plan(glm::vec3(0.0f), with(all, true), true).traces());
}

// Glass that fills little of its bounding sphere (six small balls in one mesh, as jars on a shelf)
// and is no sphere: a target for --specular-sampling, but the default chains have nothing to aim
// at, so no vertex asks for a plan. The Cornell box's spheres get both kinds of chain.
TEST(SpecularChainSampler, TracesAnyOnlyWhereAPlanCanHaveCandidates) {
  Scene scene = make_cornell_box(false);
  const int glass = static_cast<int>(scene.materials.size());
  scene.materials.push_back(make_glass());
  Mesh spread;
  spread.material = glass;
  for (int axis = 0; axis < 3; ++axis)
    for (float sign : {-1.0f, 1.0f}) {
      glm::vec3 c(0.0f, -0.5f, 0.0f);
      c[axis] += sign * 0.4f;
      const Mesh small = make_sphere(c, 0.05f, glass, 8, 4);
      const uint32_t base = static_cast<uint32_t>(spread.positions.size());
      spread.positions.insert(spread.positions.end(), small.positions.begin(), small.positions.end());
      spread.normals.insert(spread.normals.end(), small.normals.begin(), small.normals.end());
      spread.uv0.insert(spread.uv0.end(), small.uv0.begin(), small.uv0.end());
      for (const glm::uvec3& t : small.triangles) spread.triangles.push_back(t + glm::uvec3(base));
    }
  scene.meshes.push_back(spread);
  const Chains jars(scene);
  ASSERT_FALSE(jars.sampler.empty());
  EXPECT_TRUE(jars.sampler.traces_any(with(true, false)));
  EXPECT_FALSE(jars.sampler.traces_any(with(false, true)));
  EXPECT_FALSE(jars.sampler.traces_any(with(false, false)));
  for (const glm::vec3& p : points_in_the_box())
    for (bool first : {true, false}) EXPECT_FALSE(jars.sampler.plan(p, with(false, true), first).traces());

  const Chains spheres(cornell(false));
  EXPECT_TRUE(spheres.sampler.traces_any(with(false, true)));
  EXPECT_TRUE(spheres.sampler.traces_any(with(true, false)));
  EXPECT_FALSE(spheres.sampler.traces_any(with(false, false)));
}

// A plan's candidates are the targets it includes; every target with --specular-sampling, none
// with the chains off, else the near ones at the first vertex or the mirror spheres 1 time in 20.
TEST(SpecularChainSampler, PlanCountsTheTargetsItIncludes) {
  const Chains c(cornell(false));
  ASSERT_EQ(c.sampler.targets().size(), 2u);
  int near = 0, far = 0;
  for (const glm::vec3& p : points_in_the_box())
    for (bool first : {true, false}) {
      const SpecularChainSampler::Plan all = c.sampler.plan(p, with(true, false), first);
      EXPECT_EQ(all.candidates, 2);
      EXPECT_EQ(all.probability, 1.0f);
      EXPECT_FALSE(c.sampler.plan(p, with(false, false), first).traces());
      const SpecularChainSampler::Plan plan = c.sampler.plan(p, with(false, true), first);
      ASSERT_TRUE(plan.traces());
      EXPECT_EQ(plan.candidates, included(c.sampler, plan, p));
      if (plan.targets == SpecularChainSampler::Plan::Targets::Near) {
        EXPECT_TRUE(first);
        EXPECT_EQ(plan.probability, 1.0f);
        ++near;
      } else {
        EXPECT_EQ(plan.targets, SpecularChainSampler::Plan::Targets::Casters);
        EXPECT_EQ(plan.candidates, 1);  // the mirror sphere
        EXPECT_FLOAT_EQ(plan.probability, 0.05f);
        ++far;
      }
    }
  EXPECT_GT(near, 0);
  EXPECT_GT(far, 0);
}

// Every direction sample() draws carries the density pdf() gives it (the solved draws' own, not
// solved for again, agrees with solving again).
TEST(SpecularChainSampler, SampledDirectionsCarryTheirPdf) {
  for (bool env : {false, true}) {
    const Chains c(cornell(env));
    Rng rng(7, 0, env);
    int drawn = 0;
    for (const glm::vec3& p : points_in_the_box())
      for (bool all : {false, true}) {
        const SpecularChainSampler::Plan plan = c.sampler.plan(p, with(all, true), true);
        if (!plan.traces()) continue;
        for (int i = 0; i < 16; ++i) {
          SpecularChainSampler::Direction d;
          if (!c.sampler.sample(p, plan, rng.next_float() * plan.probability, rng.next_2d(), &d)) continue;
          ++drawn;
          ASSERT_GT(d.pdf, 0.0f);
          EXPECT_NEAR(c.sampler.pdf(p, d.wi, plan), d.pdf, 2e-3f * d.pdf) << p.x << " " << p.y << " " << p.z;
        }
      }
    EXPECT_GT(drawn, 1000);
  }
}

// With the sky as well, the spheres' chains mix their cone with the solved draws, so the directions
// drawn cover each cone: the mean of 1 / pdf over the draws (0 for no draw) is the solid angle of
// the cones the plan aims at (Monte Carlo, within 4 standard errors).
TEST(SpecularChainSampler, OneOverPdfIntegratesToTheConesSolidAngle) {
  const Chains c(cornell(true));
  const glm::vec3 p(0.0f, -0.95f, 0.6f);  // on the floor, in front of both spheres
  for (bool all : {false, true}) {
    const SpecularChainSampler::Plan plan = c.sampler.plan(p, with(all, true), false);
    ASSERT_TRUE(plan.traces());
    double expected = 0.0;
    for (const SpecularChainSampler::Target& t : c.sampler.targets()) {
      if (!plan.includes(t, p)) continue;
      const double d2 = glm::dot(glm::dvec3(t.center - p), glm::dvec3(t.center - p));
      expected += 2.0 * kPi * (1.0 - std::sqrt(1.0 - double(t.radius) * t.radius / d2));
    }
    Rng rng(11, 1, all);
    const int n = 200000;
    double sum = 0.0, sum2 = 0.0;
    for (int i = 0; i < n; ++i) {
      SpecularChainSampler::Direction d;
      if (!c.sampler.sample(p, plan, rng.next_float(), rng.next_2d(), &d)) continue;
      const double x = 1.0 / d.pdf;
      sum += x;
      sum2 += x * x;
    }
    const double mean = sum / n, error = std::sqrt((sum2 / n - mean * mean) / n);
    EXPECT_NEAR(mean, expected, 4.0 * error + 1e-3 * expected) << (all ? "all" : "chains") << " " << error;
  }
}

}  // namespace
}  // namespace pxf
