// The tracer on scenes the glTF loader read: what the loader's tests (scene/scene_load_test.cpp)
// cannot see without tracing, a mapped coat normal at a surface point and the default light's
// environment lighting a bare model.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "image/image.h"
#include "pathtracer/embree_scene.h"
#include "pathtracer/pathtracer.h"
#include "scene/load.h"
#include "testing/gltf_builder.h"

namespace pxf {
namespace {

using test::encode_png;
using test::GltfBuilder;

std::string temp_dir() { return test::fixture_dir("pxf_loaded_scene_"); }

TEST(LoadedScene, ClearcoatNormalMapTiltsTheCoatNormalOnly) {
  std::string dir = temp_dir();
  GltfBuilder b;
  b.doc["extensionsUsed"] = {"KHR_materials_clearcoat"};
  // A normal map tilted towards +T (tangent +X on this quad): n = normalize(T + N) at scale 1.
  const int tilted = b.texture(b.image(encode_png(1, 1, 3, 8, {255, 128, 255})));
  const int coated = b.material({{"extensions",
                                  {{"KHR_materials_clearcoat",
                                    {{"clearcoatFactor", 0.8},
                                     {"clearcoatNormalTexture", {{"index", tilted}, {"scale", 1.0}}}}}}}});
  b.add_quad_scene(coated);
  const Scene scene = load_scene(b.write_gltf(dir + "/coat.gltf"));
  // The coat's normal is mapped, the base's (no normalTexture) is the vertex normal.
  EmbreeScene geometry(scene);
  const Ray ray{glm::vec3(0.5f, 0.5f, 1.0f), glm::vec3(0.0f, 0.0f, -1.0f)};
  const Hit hit = geometry.intersect(ray);
  ASSERT_TRUE(hit.valid());
  const SurfacePoint sp = geometry.surface_point(hit, ray);
  EXPECT_NEAR(sp.shading_normal.x, 0.0f, 1e-5f);
  EXPECT_NEAR(sp.shading_normal.y, 0.0f, 1e-5f);
  EXPECT_NEAR(sp.shading_normal.z, 1.0f, 1e-5f);
  EXPECT_NEAR(sp.clearcoat_normal.z, std::sqrt(0.5f), 0.01f);
  EXPECT_NEAR(std::abs(sp.clearcoat_normal.x), std::sqrt(0.5f), 0.01f);
}

TEST(SceneLoadDefaultLight, SceneWithoutLightsGetsTheBuiltInEnvironmentAndRendersLit) {
  std::string dir = temp_dir();
  GltfBuilder b;
  b.add_quad_scene(b.material({{"pbrMetallicRoughness", {{"metallicFactor", 0.0}}}}));
  std::string path = b.write_gltf(dir + "/bare.gltf");
  for (DefaultLight light : {DefaultLight::Sky, DefaultLight::Studio}) {
    const Scene scene = load_scene(path, "", 1.0f, light);
    ASSERT_TRUE(scene.environment.has_value()) << default_light_name(light);
    ASSERT_EQ(scene.notes.size(), 1u);
    EXPECT_NE(scene.notes[0].find("built-in " + default_light_name(light)), std::string::npos) << scene.notes[0];
    TraceParams params;
    params.threads = 1;
    ProgressiveRenderer renderer(scene, params, 8, 8);
    EXPECT_FALSE(renderer.scene_is_dark());
    for (int i = 0; i < 4; ++i) renderer.add_frame();
    const Accumulation& acc = renderer.accumulation();
    // The quad faces the default camera and fills the middle of the image: lit, not black.
    size_t center = 4 * 8 + 4;
    glm::vec3 c = acc.lv_mean[center] + acc.hv_mean[center];
    EXPECT_GT(luminance(c.x, c.y, c.z), 0.05f) << default_light_name(light);
  }
}

}  // namespace
}  // namespace pxf
