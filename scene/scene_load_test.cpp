// Loader tests. Each test writes a tiny glTF (JSON + base64 data-URI buffer, or .glb) into a temp
// directory, so every feature and every bad-input case has its own minimal, readable fixture.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>

#include "core/json_depth.h"
#include "image/image.h"
#include "scene/camera.h"
#include "scene/load.h"
#include "scene/texture.h"
#include "testing/glb_test_util.h"
#include "testing/gltf_builder.h"

namespace pxf {
namespace {

using json = nlohmann::json;
namespace fs = std::filesystem;
using test::encode_png;
using test::GltfBuilder;
using test::write_bytes;

// ----------------------------------------------------------------------------------------------
// Fixtures

std::string temp_dir() { return test::fixture_dir("pxf_scene_load_"); }

// ----------------------------------------------------------------------------------------------
// Assertions

void expect_vec3_near(glm::vec3 a, glm::vec3 b, float eps = 1e-5f) {
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(a[i], b[i], eps) << "component " << i << " of (" << a.x << ", " << a.y << ", " << a.z << ")";
}

bool any_warning_contains(const Scene& scene, const std::string& text) {
  for (const std::string& w : scene.warnings)
    if (w.find(text) != std::string::npos) return true;
  return false;
}

std::string warnings_of(const Scene& scene) {
  std::string all;
  for (const std::string& w : scene.warnings) all += w + "\n";
  return all;
}

// Every float the loader produced is finite.
void expect_scene_finite(const Scene& scene) {
  for (const Mesh& m : scene.meshes) {
    for (const glm::vec3& p : m.positions) ASSERT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
    for (const glm::vec3& n : m.normals) {
      ASSERT_TRUE(std::isfinite(n.x) && std::isfinite(n.y) && std::isfinite(n.z));
      ASSERT_NEAR(glm::length(n), 1.0f, 1e-4f);
    }
    for (const glm::vec4& t : m.tangents) ASSERT_TRUE(std::isfinite(t.x) && std::isfinite(t.y) && std::isfinite(t.z) && std::isfinite(t.w));
    EXPECT_EQ(m.normals.size(), m.positions.size());
  }
}

// Runs `load` and returns the pxf::Error message (fails the test when nothing is thrown).
template <typename F>
std::string error_of(F&& load) {
  try {
    load();
  } catch (const Error& e) {
    std::string message = e.what();
    EXPECT_EQ(message.find('\n'), std::string::npos) << "error must be one line: " << message;
    return message;
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected pxf::Error, got " << e.what();
    return e.what();
  }
  ADD_FAILURE() << "expected pxf::Error, nothing was thrown";
  return "";
}


json rotation_json(float angle, glm::vec3 axis) {
  glm::vec3 a = glm::normalize(axis) * std::sin(angle / 2);
  return json::array({a.x, a.y, a.z, std::cos(angle / 2)});
}

// ----------------------------------------------------------------------------------------------
// Geometry

TEST(SceneLoadGeometry, HierarchyFlattensTransformsToWorldSpace) {
  std::string dir = temp_dir();
  GltfBuilder b;
  int quad = b.mesh(b.quad_primitive());
  int child = b.node({{"mesh", quad}, {"rotation", rotation_json(1.5707963f, {0, 1, 0})}});
  int matrix_child = b.node({{"mesh", quad}, {"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 5, 1}}});
  int parent = b.node({{"translation", {1, 2, 3}}, {"scale", {2, 2, 2}}, {"children", {child, matrix_child}}});
  b.scene({parent});
  Scene scene = load_scene(b.write_gltf(dir + "/h.gltf"));
  ASSERT_EQ(scene.meshes.size(), 2u);
  // Child: rotate (1,0,0) a quarter turn about +Y -> (0,0,-1), scale 2, translate (1,2,3).
  const Mesh& rotated = scene.meshes[0];
  expect_vec3_near(rotated.positions[1], {1, 2, 1});
  expect_vec3_near(rotated.positions[2], {1, 4, 1});
  for (const glm::vec3& n : rotated.normals) expect_vec3_near(n, {1, 0, 0});  // +Z turned to +X
  // Matrix child: local translation (0,0,5) scaled by 2 -> z = 3 + 10.
  expect_vec3_near(scene.meshes[1].positions[2], {1 + 2, 2 + 2, 13});
  EXPECT_EQ(scene.triangle_count(), 4u);
  expect_scene_finite(scene);
}

TEST(SceneLoadGeometry, NonUniformScaleUsesInverseTransposeForNormals) {
  std::string dir = temp_dir();
  GltfBuilder b;
  float s = 1.0f / std::sqrt(2.0f);
  json prim = {{"attributes",
                {{"POSITION", b.floats({0, 0, 0, 1, 0, 0, 0, 1, -1}, "VEC3")},
                 {"NORMAL", b.floats({0, s, s, 0, s, s, 0, s, s}, "VEC3")}}}};
  b.scene({b.node({{"mesh", b.mesh(prim)}, {"scale", {1, 4, 1}}})});
  Scene scene = load_scene(b.write_gltf(dir + "/s.gltf"));
  ASSERT_EQ(scene.meshes.size(), 1u);
  // World triangle (0,0,0) (1,0,0) (0,4,-1) has normal (0,1,4)/|.|.
  expect_vec3_near(scene.meshes[0].normals[0], glm::normalize(glm::vec3(0, 1, 4)));
}

TEST(SceneLoadGeometry, MirroringTransformKeepsComputedNormalsFacingOut) {
  std::string dir = temp_dir();
  GltfBuilder b;
  b.scene({b.node({{"mesh", b.mesh(b.quad_primitive())}, {"scale", {-1, 1, 1}}})});
  Scene scene = load_scene(b.write_gltf(dir + "/m.gltf"));
  ASSERT_EQ(scene.meshes.size(), 1u);
  // Mirroring x flips the winding; the loader restores it, so the face still points to +Z.
  for (const glm::vec3& n : scene.meshes[0].normals) expect_vec3_near(n, {0, 0, 1});
}

TEST(SceneLoadGeometry, IndexedAndNonIndexedGiveTheSameTriangles) {
  std::string dir = temp_dir();
  GltfBuilder b;
  json indexed = b.quad_primitive();
  json flat = {{"attributes", {{"POSITION", b.floats({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 0, 0, 1, 1, 0, 0, 1, 0}, "VEC3")}}}};
  b.scene({b.node({{"mesh", b.mesh(indexed)}}), b.node({{"mesh", b.mesh(flat)}})});
  Scene scene = load_scene(b.write_gltf(dir + "/i.gltf"));
  ASSERT_EQ(scene.meshes.size(), 2u);
  ASSERT_EQ(scene.meshes[0].triangles.size(), 2u);
  ASSERT_EQ(scene.meshes[1].triangles.size(), 2u);
  for (int t = 0; t < 2; ++t)
    for (int k = 0; k < 3; ++k)
      expect_vec3_near(scene.meshes[0].positions[scene.meshes[0].triangles[t][k]],
                       scene.meshes[1].positions[scene.meshes[1].triangles[t][k]]);
  EXPECT_EQ(scene.meshes[1].positions.size(), 6u);
}

TEST(SceneLoadGeometry, TriangleStripAndFanAreTriangulated) {
  std::string dir = temp_dir();
  GltfBuilder b;
  int pos = b.floats({0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0}, "VEC3");
  json strip = {{"attributes", {{"POSITION", pos}}}, {"mode", 5}};
  json fan = {{"attributes", {{"POSITION", pos}}}, {"mode", 6}, {"indices", b.indices({0, 1, 3, 2})}};
  b.scene({b.node({{"mesh", b.mesh(strip)}}), b.node({{"mesh", b.mesh(fan)}})});
  Scene scene = load_scene(b.write_gltf(dir + "/strip.gltf"));
  ASSERT_EQ(scene.meshes.size(), 2u);
  EXPECT_EQ(scene.meshes[0].triangles.size(), 2u);
  EXPECT_EQ(scene.meshes[1].triangles.size(), 2u);
  for (const Mesh& m : scene.meshes)
    for (const glm::vec3& n : m.normals) expect_vec3_near(n, {0, 0, 1});  // strip winding alternates correctly
}

TEST(SceneLoadGeometry, NonTriangleModesAreSkippedWithAWarning) {
  std::string dir = temp_dir();
  GltfBuilder b;
  json lines = {{"attributes", {{"POSITION", b.floats({0, 0, 0, 1, 0, 0}, "VEC3")}}}, {"mode", 1}};
  b.scene({b.node({{"mesh", b.mesh(lines)}}), b.node({{"mesh", b.mesh(b.quad_primitive())}})});
  Scene scene = load_scene(b.write_gltf(dir + "/lines.gltf"));
  EXPECT_EQ(scene.meshes.size(), 1u);
  EXPECT_TRUE(any_warning_contains(scene, "mode 1")) << warnings_of(scene);
}

TEST(SceneLoadGeometry, GlbLoadsLikeGltf) {
  std::string dir = temp_dir();
  GltfBuilder b;
  b.add_quad_scene();
  Scene text = load_scene(b.write_gltf(dir + "/q.gltf"));
  Scene binary = load_scene(b.write_glb(dir + "/q.glb"));
  ASSERT_EQ(binary.meshes.size(), 1u);
  EXPECT_EQ(binary.meshes[0].positions, text.meshes[0].positions);
  EXPECT_EQ(binary.meshes[0].uv0, text.meshes[0].uv0);
  EXPECT_EQ(binary.triangle_count(), 2u);
}

TEST(SceneLoadGeometry, MissingNormalsAreAreaWeightedOrFlat) {
  std::string dir = temp_dir();
  GltfBuilder b;
  // Two triangles folded 90 degrees along the x axis; the small one (area 1/2) faces +Z, the big one
  // (area 1) faces +Y. Shared vertices get the area-weighted average (0, 1, 1/2).
  json folded = {{"attributes", {{"POSITION", b.floats({0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, -2}, "VEC3")}}},
                 {"indices", b.indices({0, 1, 2, 0, 1, 3})}};
  json flat = {{"attributes", {{"POSITION", b.floats({0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, -2}, "VEC3")}}}};
  b.scene({b.node({{"mesh", b.mesh(folded)}}), b.node({{"mesh", b.mesh(flat)}})});
  Scene scene = load_scene(b.write_gltf(dir + "/n.gltf"));
  ASSERT_EQ(scene.meshes.size(), 2u);
  const Mesh& smooth = scene.meshes[0];
  expect_vec3_near(smooth.normals[0], glm::normalize(glm::vec3(0, 1, 0.5f)));
  expect_vec3_near(smooth.normals[1], glm::normalize(glm::vec3(0, 1, 0.5f)));
  expect_vec3_near(smooth.normals[2], {0, 0, 1});
  expect_vec3_near(smooth.normals[3], {0, 1, 0});
  const Mesh& faceted = scene.meshes[1];
  for (int v = 0; v < 3; ++v) expect_vec3_near(faceted.normals[v], {0, 0, 1});
  for (int v = 3; v < 6; ++v) expect_vec3_near(faceted.normals[v], {0, 1, 0});
}

TEST(SceneLoadGeometry, ZeroAndNanNormalsAreReplacedByGeometricNormals) {
  std::string dir = temp_dir();
  GltfBuilder b;
  float nan = std::numeric_limits<float>::quiet_NaN();
  json prim = {{"attributes",
                {{"POSITION", b.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3")},
                 {"NORMAL", b.floats({0, 0, 0, nan, 0, 1, 0, 0, 3}, "VEC3")}}}};
  b.scene({b.node({{"mesh", b.mesh(prim)}})});
  Scene scene = load_scene(b.write_gltf(dir + "/z.gltf"));
  ASSERT_EQ(scene.meshes.size(), 1u);
  for (const glm::vec3& n : scene.meshes[0].normals) expect_vec3_near(n, {0, 0, 1});
  expect_scene_finite(scene);
}

TEST(SceneLoadGeometry, MissingTangentsAreOrthonormalWithUvHandedness) {
  std::string dir = temp_dir();
  GltfBuilder b;
  int normal_png = b.image(encode_png(1, 1, 3, 8, {128, 128, 255}));
  int mat = b.material({{"normalTexture", {{"index", b.texture(normal_png)}, {"scale", 0.5}}}});
  json regular = b.quad_primitive(mat);
  json mirrored = b.quad_primitive(mat);
  mirrored["attributes"]["TEXCOORD_0"] = b.floats({1, 1, 0, 1, 0, 0, 1, 0}, "VEC2");  // u runs along -x
  json degenerate_uv = b.quad_primitive(mat);
  degenerate_uv["attributes"]["TEXCOORD_0"] = b.floats({0, 0, 0, 0, 0, 0, 0, 0}, "VEC2");
  b.scene({b.node({{"mesh", b.mesh(regular)}}), b.node({{"mesh", b.mesh(mirrored)}}), b.node({{"mesh", b.mesh(degenerate_uv)}})});
  Scene scene = load_scene(b.write_gltf(dir + "/t.gltf"));
  ASSERT_EQ(scene.meshes.size(), 3u);
  EXPECT_FLOAT_EQ(scene.materials[0].normal_scale, 0.5f);
  EXPECT_TRUE(scene.materials[0].normal_texture.valid());
  for (const Mesh& m : scene.meshes) {
    ASSERT_EQ(m.tangents.size(), m.positions.size());
    for (size_t i = 0; i < m.tangents.size(); ++i) {
      glm::vec3 t(m.tangents[i]);
      EXPECT_NEAR(glm::length(t), 1.0f, 1e-5f);
      EXPECT_NEAR(glm::dot(t, m.normals[i]), 0.0f, 1e-5f);
      EXPECT_TRUE(m.tangents[i].w == 1.0f || m.tangents[i].w == -1.0f);
    }
  }
  for (const glm::vec4& t : scene.meshes[0].tangents) {
    expect_vec3_near(glm::vec3(t), {1, 0, 0});
    EXPECT_EQ(t.w, 1.0f);  // bitangent cross(n, t) * w = +Y = towards smaller glTF v
  }
  for (const glm::vec4& t : scene.meshes[1].tangents) {
    expect_vec3_near(glm::vec3(t), {-1, 0, 0});
    EXPECT_EQ(t.w, -1.0f);  // mirrored UVs flip the handedness
  }
}

TEST(SceneLoadGeometry, ProvidedTangentsFollowTheTransform) {
  std::string dir = temp_dir();
  GltfBuilder b;
  int mat = b.material({{"normalTexture", {{"index", b.texture(b.image(encode_png(1, 1, 3, 8, {128, 128, 255})))}}}});
  json prim = b.quad_primitive(mat);
  prim["attributes"]["TANGENT"] = b.floats({1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1}, "VEC4");
  b.scene({b.node({{"mesh", b.mesh(prim)}, {"scale", {-1, 1, 1}}})});
  Scene scene = load_scene(b.write_gltf(dir + "/pt.gltf"));
  ASSERT_EQ(scene.meshes.size(), 1u);
  for (const glm::vec4& t : scene.meshes[0].tangents) {
    expect_vec3_near(glm::vec3(t), {-1, 0, 0});
    EXPECT_EQ(t.w, -1.0f);
  }
}

TEST(SceneLoadGeometry, TexcoordSet1AndVertexColors) {
  std::string dir = temp_dir();
  GltfBuilder b;
  json f3 = b.quad_primitive();
  f3["attributes"]["TEXCOORD_1"] = b.floats({0.5f, 0.5f, 1, 0.5f, 1, 0, 0.5f, 0}, "VEC2");
  f3["attributes"]["COLOR_0"] = b.floats({1, 0, 0, 0, 1, 0, 0, 0, 1, 0.5f, 0.5f, 0.5f}, "VEC3");
  json u16 = b.quad_primitive();
  std::vector<uint16_t> c16 = {65535, 0, 0, 32768, 0, 65535, 0, 65535, 0, 0, 65535, 0, 65535, 65535, 65535, 0};
  u16["attributes"]["COLOR_0"] = b.accessor(b.view(c16.data(), c16.size() * 2), 5123, 4, "VEC4", true);
  json u8 = b.quad_primitive();
  std::vector<uint8_t> c8 = {255, 0, 0, 255, 0, 51, 0, 255, 0, 0, 255, 0, 255, 255, 255, 255};
  u8["attributes"]["COLOR_0"] = b.accessor(b.view(c8.data(), c8.size()), 5121, 4, "VEC4", true);
  b.scene({b.node({{"mesh", b.mesh(f3)}}), b.node({{"mesh", b.mesh(u16)}}), b.node({{"mesh", b.mesh(u8)}})});
  Scene scene = load_scene(b.write_gltf(dir + "/c.gltf"));
  ASSERT_EQ(scene.meshes.size(), 3u);
  ASSERT_EQ(scene.meshes[0].uv1.size(), 4u);
  EXPECT_EQ(scene.meshes[0].uv1[1], glm::vec2(1, 0.5f));
  EXPECT_EQ(scene.meshes[0].colors[3], glm::vec4(0.5f, 0.5f, 0.5f, 1.0f));  // vec3 gets alpha 1
  EXPECT_NEAR(scene.meshes[1].colors[0].w, 32768.0f / 65535.0f, 1e-6f);
  EXPECT_EQ(scene.meshes[1].colors[1], glm::vec4(0, 1, 0, 1));
  EXPECT_NEAR(scene.meshes[2].colors[1].y, 0.2f, 1e-6f);
  EXPECT_TRUE(scene.meshes[2].uv1.empty());
}

// ----------------------------------------------------------------------------------------------
// Camera, lights, defaults

// A yfov outside (1e-4, 3.1) radians gets the default field of view, and a warning says so.
TEST(SceneLoadCamera, OutOfRangeYfovIsReplacedWithAWarning) {
  std::string dir = temp_dir();
  for (double yfov : {1e-30, 3.14159265358979, 4.0}) {
    GltfBuilder b;
    b.doc["cameras"] = {{{"type", "perspective"}, {"perspective", {{"yfov", yfov}, {"znear", 0.1}}}}};
    int cam = b.node({{"camera", 0}, {"translation", {0, 0, 5}}});
    int quad = b.node({{"mesh", b.mesh(b.quad_primitive())}});
    b.scene({quad, cam});
    Scene scene = load_scene(b.write_gltf(dir + "/yfov.gltf"));
    EXPECT_FLOAT_EQ(scene.camera.yfov, Camera{}.yfov) << yfov;
    EXPECT_TRUE(any_warning_contains(scene, "camera 0 has a yfov of")) << yfov << ": " << warnings_of(scene);
  }
  GltfBuilder b;
  b.doc["cameras"] = {{{"type", "perspective"}, {"perspective", {{"yfov", 0.7}, {"znear", 0.1}}}}};
  int cam = b.node({{"camera", 0}, {"translation", {0, 0, 5}}});
  b.scene({b.node({{"mesh", b.mesh(b.quad_primitive())}}), cam});
  Scene scene = load_scene(b.write_gltf(dir + "/fine.gltf"));
  EXPECT_FLOAT_EQ(scene.camera.yfov, 0.7f);
  EXPECT_FALSE(any_warning_contains(scene, "yfov")) << warnings_of(scene);
}

TEST(SceneLoadCamera, FirstCameraInHierarchyWithRigidWorldFrame) {
  std::string dir = temp_dir();
  GltfBuilder b;
  b.doc["cameras"] = {{{"type", "perspective"}, {"perspective", {{"yfov", 0.5}, {"znear", 0.1}, {"zfar", 100}, {"aspectRatio", 1.5}}}},
                      {{"type", "perspective"}, {"perspective", {{"yfov", 1.0}, {"znear", 0.2}}}}};
  int cam = b.node({{"camera", 0}, {"rotation", rotation_json(1.5707963f, {0, 1, 0})}});
  int parent = b.node({{"translation", {0, 0, 10}}, {"scale", {3, 3, 3}}, {"children", {cam}}});
  int quad = b.node({{"mesh", b.mesh(b.quad_primitive())}});
  int second = b.node({{"camera", 1}});
  b.scene({quad, parent, second});
  Scene scene = load_scene(b.write_gltf(dir + "/cam.gltf"));
  const Camera& c = scene.camera;
  EXPECT_FLOAT_EQ(c.yfov, 0.5f);
  EXPECT_FLOAT_EQ(c.znear, 0.1f);
  EXPECT_FLOAT_EQ(c.zfar, 100.0f);
  EXPECT_FLOAT_EQ(c.aspect, 1.5f);
  expect_vec3_near(glm::vec3(c.camera_to_world[3]), {0, 0, 10});
  expect_vec3_near(glm::vec3(c.camera_to_world[2]), {1, 0, 0});  // +Z of the camera turned to +X, scale removed
  expect_vec3_near(glm::vec3(c.camera_to_world[1]), {0, 1, 0});
  expect_vec3_near(glm::vec3(c.camera_to_world[0]), {0, 0, -1});
}

TEST(SceneLoadCamera, DefaultCameraFramesTheSceneBounds) {
  std::string dir = temp_dir();
  GltfBuilder b;
  b.scene({b.node({{"mesh", b.mesh(b.quad_primitive())}, {"translation", {10, 0, 0}}})});
  Scene scene = load_scene(b.write_gltf(dir + "/nocam.gltf"));
  // The quad [10, 11] x [0, 1] at z = 0 is seen from its front, centered and inside the frame
  // (auto_camera_test.cpp checks the framing itself).
  glm::vec3 eye(scene.camera.camera_to_world[3]);
  glm::vec3 forward = -glm::vec3(scene.camera.camera_to_world[2]);
  EXPECT_GT(eye.z, 0.0f);
  glm::vec3 to_center = glm::normalize(glm::vec3(10.5f, 0.5f, 0.0f) - eye);
  EXPECT_GT(glm::dot(to_center, forward), 0.999f);
  for (glm::vec3 corner : {glm::vec3(10, 0, 0), glm::vec3(11, 1, 0)}) {
    glm::vec3 q = corner - eye;
    float depth = glm::dot(q, forward);
    EXPECT_LT(std::fabs(glm::dot(q, glm::vec3(scene.camera.camera_to_world[1]))) / depth, std::tan(0.5f * scene.camera.yfov));
    EXPECT_GT(depth, scene.camera.znear);
    EXPECT_LT(depth, scene.camera.zfar);
  }
}

TEST(SceneLoadCamera, OrthographicCameraKeepsYmagAndItsFrame) {
  std::string dir = temp_dir();
  GltfBuilder b;
  b.doc["cameras"] = {{{"type", "orthographic"}, {"orthographic", {{"xmag", 3.0}, {"ymag", 1.5}, {"znear", 0.0}, {"zfar", 50.0}}}}};
  b.scene({b.node({{"camera", 0}, {"translation", {0, 0, 5}}}), b.node({{"mesh", b.mesh(b.quad_primitive())}})});
  Scene scene = load_scene(b.write_gltf(dir + "/ortho.gltf"));
  EXPECT_TRUE(scene.camera.orthographic);
  EXPECT_FLOAT_EQ(scene.camera.ymag, 1.5f);
  EXPECT_FLOAT_EQ(scene.camera.aspect, 2.0f);
  EXPECT_FLOAT_EQ(scene.camera.znear, 0.0f);
  EXPECT_FLOAT_EQ(scene.camera.zfar, 50.0f);
  expect_vec3_near(glm::vec3(scene.camera.camera_to_world[3]), {0, 0, 5});
  EXPECT_TRUE(scene.warnings.empty() || !any_warning_contains(scene, "camera")) << warnings_of(scene);
}

TEST(SceneLoadLights, PunctualLightsOfAllThreeTypes) {
  std::string dir = temp_dir();
  GltfBuilder b;
  b.doc["extensionsUsed"] = {"KHR_lights_punctual"};
  b.doc["extensions"]["KHR_lights_punctual"]["lights"] = {
      {{"type", "point"}, {"color", {1, 0.5, 0.25}}, {"intensity", 20}, {"range", 7}},
      {{"type", "spot"}, {"intensity", 5}, {"spot", {{"innerConeAngle", 0.2}, {"outerConeAngle", 0.6}}}},
      {{"type", "directional"}, {"intensity", 3}, {"name", "sun"}}};
  auto light_node = [&](int light, json extra) {
    json n = {{"extensions", {{"KHR_lights_punctual", {{"light", light}}}}}};
    n.update(extra);
    return b.node(n);
  };
  int point = light_node(0, {{"translation", {0, 5, 0}}});
  int spot = light_node(1, {{"translation", {1, 2, 3}}, {"rotation", rotation_json(1.5707963f, {1, 0, 0})}});
  int sun = light_node(2, {{"rotation", rotation_json(-1.5707963f, {1, 0, 0})}});
  b.scene({point, spot, sun, b.node({{"mesh", b.mesh(b.quad_primitive())}})});
  Scene scene = load_scene(b.write_gltf(dir + "/lights.gltf"));
  ASSERT_EQ(scene.lights.size(), 3u);
  const PunctualLight& p = scene.lights[0];
  EXPECT_EQ(p.type, PunctualLight::Type::Point);
  expect_vec3_near(p.position, {0, 5, 0});
  expect_vec3_near(p.color, {1, 0.5f, 0.25f});
  EXPECT_FLOAT_EQ(p.intensity, 20.0f);
  EXPECT_FLOAT_EQ(p.range, 7.0f);
  const PunctualLight& s = scene.lights[1];
  EXPECT_EQ(s.type, PunctualLight::Type::Spot);
  expect_vec3_near(s.position, {1, 2, 3});
  expect_vec3_near(s.direction, {0, 1, 0});  // -Z turned a quarter about +X points up
  EXPECT_FLOAT_EQ(s.inner_cone, 0.2f);
  EXPECT_FLOAT_EQ(s.outer_cone, 0.6f);
  const PunctualLight& d = scene.lights[2];
  EXPECT_EQ(d.type, PunctualLight::Type::Directional);
  EXPECT_EQ(d.name, "sun");
  expect_vec3_near(d.direction, {0, -1, 0});
  EXPECT_FLOAT_EQ(d.intensity, 3.0f);
  EXPECT_FALSE(any_warning_contains(scene, "KHR_lights_punctual")) << warnings_of(scene);
}

TEST(SceneLoadDefaults, SceneExtrasCarryRenderDefaults) {
  std::string dir = temp_dir();
  GltfBuilder b;
  b.scene({b.node({{"mesh", b.mesh(b.quad_primitive())}})}, {{"pxf", {{"all_hv", true}, {"width", 320}, {"height", 240}}}});
  Scene scene = load_scene(b.write_gltf(dir + "/d.gltf"));
  EXPECT_TRUE(scene.defaults.all_hv);
  EXPECT_EQ(scene.defaults.width, 320);
  EXPECT_EQ(scene.defaults.height, 240);
  GltfBuilder plain;
  plain.add_quad_scene();
  Scene other = load_scene(plain.write_gltf(dir + "/plain.gltf"));
  EXPECT_FALSE(other.defaults.all_hv);
  EXPECT_EQ(other.defaults.width, 0);
}

// ----------------------------------------------------------------------------------------------
// Materials and textures

TEST(SceneLoadMaterial, DefaultMaterialIsAppendedForPrimitivesWithout) {
  std::string dir = temp_dir();
  GltfBuilder b;
  int red = b.material({{"pbrMetallicRoughness", {{"baseColorFactor", {1, 0, 0, 1}}}}});
  b.scene({b.node({{"mesh", b.mesh(b.quad_primitive(red))}}), b.node({{"mesh", b.mesh(b.quad_primitive())}})});
  Scene scene = load_scene(b.write_gltf(dir + "/dm.gltf"));
  ASSERT_EQ(scene.materials.size(), 2u);
  EXPECT_EQ(scene.meshes[0].material, 0);
  EXPECT_EQ(scene.meshes[1].material, 1);
  EXPECT_EQ(scene.materials[1].base_color, glm::vec4(1.0f));
  EXPECT_EQ(scene.materials[1].metallic, 0.0f);
  EXPECT_EQ(scene.materials[0].metallic, 1.0f);  // glTF's default metallicFactor
}

// Emission beyond what the accumulated sums and variances can hold (a closed box at 1e30 rendered
// black, at 3.4e38 every layer 0) is clamped to 1e12, hue kept, with a warning naming the material.
TEST(SceneLoadMaterial, UnrepresentableEmissionIsClampedWithAWarningNamingTheMaterial) {
  std::string dir = temp_dir();
  for (double strength : {1e30, 3.4e38, 1e300}) {
    GltfBuilder b;
    b.doc["extensionsUsed"] = {"KHR_materials_emissive_strength"};
    int mat = b.material({{"name", "sunface"},
                          {"emissiveFactor", {1, 0.5, 0}},
                          {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", strength}}}}}});
    b.add_quad_scene(mat);
    Scene scene = load_scene(b.write_gltf(dir + "/bright.gltf"));
    const Material& m = scene.materials[0];
    EXPECT_FLOAT_EQ(m.emissive.x, 1e12f) << strength;
    EXPECT_FLOAT_EQ(m.emissive.y, 0.5e12f) << strength;
    EXPECT_EQ(m.emissive.z, 0.0f) << strength;
    EXPECT_TRUE(any_warning_contains(scene, "material 'sunface' emits")) << strength << ": " << warnings_of(scene);
    EXPECT_TRUE(any_warning_contains(scene, "clamped")) << warnings_of(scene);
  }
  GltfBuilder b;  // bright but representable: as given, no warning
  b.doc["extensionsUsed"] = {"KHR_materials_emissive_strength"};
  int mat = b.material({{"name", "lamp"},
                        {"emissiveFactor", {1, 1, 1}},
                        {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", 1e6}}}}}});
  b.add_quad_scene(mat);
  Scene scene = load_scene(b.write_gltf(dir + "/lamp.gltf"));
  EXPECT_FLOAT_EQ(scene.materials[0].emissive.x, 1e6f);
  EXPECT_FALSE(any_warning_contains(scene, "emits")) << warnings_of(scene);
}

TEST(SceneLoadMaterial, KhrExtensionsEmissiveStrengthTransmissionIorSpecular) {
  std::string dir = temp_dir();
  GltfBuilder b;
  b.doc["extensionsUsed"] = {"KHR_materials_emissive_strength", "KHR_materials_transmission", "KHR_materials_ior",
                             "KHR_materials_specular"};
  int gray = b.texture(b.image(encode_png(1, 1, 4, 8, {128, 128, 128, 64})));
  int mat = b.material({{"name", "glassy"},
                        {"emissiveFactor", {1, 0.5, 0.25}},
                        {"pbrMetallicRoughness", {{"metallicFactor", 0.0}, {"roughnessFactor", 0.25}}},
                        {"extensions",
                         {{"KHR_materials_emissive_strength", {{"emissiveStrength", 8}}},
                          {"KHR_materials_transmission", {{"transmissionFactor", 0.9}, {"transmissionTexture", {{"index", gray}}}}},
                          {"KHR_materials_ior", {{"ior", 1.33}}},
                          {"KHR_materials_specular",
                           {{"specularFactor", 0.3},
                            {"specularTexture", {{"index", gray}}},
                            {"specularColorFactor", {0.5, 0.6, 0.7}},
                            {"specularColorTexture", {{"index", gray}}}}}}}});
  b.add_quad_scene(mat);
  Scene scene = load_scene(b.write_gltf(dir + "/ext.gltf"));
  const Material& m = scene.materials[0];
  EXPECT_EQ(m.name, "glassy");
  expect_vec3_near(m.emissive, {8, 4, 2});
  EXPECT_TRUE(m.is_emissive());
  EXPECT_FLOAT_EQ(m.transmission, 0.9f);
  EXPECT_FLOAT_EQ(m.ior, 1.33f);
  EXPECT_FLOAT_EQ(m.specular, 0.3f);
  expect_vec3_near(m.specular_color, {0.5f, 0.6f, 0.7f});
  EXPECT_FLOAT_EQ(m.roughness, 0.25f);
  EXPECT_FLOAT_EQ(m.metallic, 0.0f);
  ASSERT_TRUE(m.transmission_texture.valid() && m.specular_texture.valid() && m.specular_color_texture.valid());
  // The specular/transmission textures are linear; the specular color texture is sRGB-decoded.
  EXPECT_NEAR(scene.textures[m.specular_texture.texture].texel(0).x, 128 / 255.0f, 1e-6f);
  EXPECT_NEAR(scene.textures[m.specular_texture.texture].texel(0).w, 64 / 255.0f, 1e-6f);
  EXPECT_NEAR(scene.textures[m.specular_color_texture.texture].texel(0).x, linear_from_srgb(128 / 255.0f), 1e-6f);
  EXPECT_EQ(m.specular_texture.texture, m.transmission_texture.texture);  // one linear copy shared
  EXPECT_NE(m.specular_texture.texture, m.specular_color_texture.texture);
  EXPECT_TRUE(scene.warnings.empty()) << warnings_of(scene);
}

// KHR_materials_pbrSpecularGlossiness is converted at load, with one warning per file; a file
// that requires it loads.
TEST(SceneLoadMaterial, SpecularGlossinessFactorsConvertToMetallicRoughness) {
  std::string dir = temp_dir();
  GltfBuilder b;
  b.doc["extensionsUsed"] = {"KHR_materials_pbrSpecularGlossiness"};
  b.doc["extensionsRequired"] = {"KHR_materials_pbrSpecularGlossiness"};
  auto spec_gloss = [&](const std::string& name, json ext) {
    // The metallic-roughness block is the file's fallback for viewers without the extension.
    return b.material({{"name", name},
                       {"pbrMetallicRoughness", {{"baseColorFactor", {0, 1, 0, 1}}, {"metallicFactor", 0.5}}},
                       {"extensions", {{"KHR_materials_pbrSpecularGlossiness", ext}}}});
  };
  int plastic = spec_gloss("plastic", {{"diffuseFactor", {0.6, 0.3, 0.1, 0.8}},
                                       {"specularFactor", {0.04, 0.04, 0.04}},
                                       {"glossinessFactor", 0.7}});
  int gold = spec_gloss("gold", {{"diffuseFactor", {0, 0, 0, 1}},
                                 {"specularFactor", {1.0, 0.78, 0.34}},
                                 {"glossinessFactor", 0.9}});
  int defaults = spec_gloss("defaults", json::object());
  b.scene({b.node({{"mesh", b.mesh(b.quad_primitive(plastic))}}), b.node({{"mesh", b.mesh(b.quad_primitive(gold))}}),
           b.node({{"mesh", b.mesh(b.quad_primitive(defaults))}})});
  Scene scene = load_scene(b.write_gltf(dir + "/sg.gltf"));
  ASSERT_EQ(scene.materials.size(), 4u);

  const Material& p = scene.materials[0];
  EXPECT_NEAR(p.metallic, 0.0f, 1e-4f);
  expect_vec3_near(p.base_color, {0.6f, 0.3f, 0.1f}, 1e-4f);
  EXPECT_NEAR(p.base_color.a, 0.8f, 1e-6f);
  EXPECT_NEAR(p.roughness, 0.3f, 1e-6f);
  EXPECT_FALSE(p.base_color_texture.valid() || p.metallic_roughness_texture.valid());

  const Material& g = scene.materials[1];
  EXPECT_GT(g.metallic, 0.999f);
  expect_vec3_near(g.base_color, {1.0f, 0.78f, 0.34f}, 1e-3f);
  EXPECT_NEAR(g.roughness, 0.1f, 1e-6f);

  // Defaults: white diffuse, white specular, glossiness 1: a smooth white metal.
  const Material& d = scene.materials[2];
  EXPECT_GT(d.metallic, 0.999f);
  EXPECT_EQ(d.roughness, 0.0f);
  expect_vec3_near(d.base_color, {1, 1, 1}, 1e-3f);

  size_t lines = 0;
  for (const std::string& w : scene.warnings)
    if (w.find("KHR_materials_pbrSpecularGlossiness") != std::string::npos) {
      ++lines;
      EXPECT_NE(w.find("3 "), std::string::npos) << w;  // the count of converted materials
      EXPECT_EQ(w.find("approximated"), std::string::npos) << w;
    }
  EXPECT_EQ(lines, 1u) << warnings_of(scene);
  EXPECT_FALSE(any_warning_contains(scene, "unsupported")) << warnings_of(scene);
}

TEST(SceneLoadMaterial, SpecularGlossinessTexturesAreBakedPerTexel) {
  std::string dir = temp_dir();
  GltfBuilder b;
  b.doc["extensionsUsed"] = {"KHR_materials_pbrSpecularGlossiness", "KHR_texture_transform"};
  // 2x1: texel 0 an orange dielectric (dark specular), texel 1 a metal (black diffuse, bright specular).
  int diffuse = b.texture(b.image(encode_png(2, 1, 4, 8, {220, 120, 40, 255, 0, 0, 0, 255})), {{"sampler", 0}});
  int spec = b.texture(b.image(encode_png(2, 1, 4, 8, {56, 56, 56, 102, 250, 210, 130, 230})), {{"sampler", 0}});
  b.doc["samplers"] = {{{"magFilter", 9728}, {"wrapS", 33071}}};  // NEAREST, clamp to edge
  json offset = {{"KHR_texture_transform", {{"offset", {0.25, 0}}}}};
  int baked = b.material({{"name", "baked"},
                          {"extensions",
                           {{"KHR_materials_pbrSpecularGlossiness",
                             {{"diffuseTexture", {{"index", diffuse}, {"extensions", offset}}},
                              {"specularGlossinessTexture", {{"index", spec}, {"extensions", offset}}},
                              {"glossinessFactor", 0.5}}}}}});
  // Different UV mappings cannot be baked into one texture: approximated, and said so.
  int mixed = b.material({{"name", "mixed"},
                          {"extensions",
                           {{"KHR_materials_pbrSpecularGlossiness",
                             {{"diffuseTexture", {{"index", diffuse}, {"extensions", offset}}},
                              {"specularGlossinessTexture", {{"index", spec}}}}}}}});
  b.scene({b.node({{"mesh", b.mesh(b.quad_primitive(baked))}}), b.node({{"mesh", b.mesh(b.quad_primitive(mixed))}})});
  Scene scene = load_scene(b.write_gltf(dir + "/sgtex.gltf"));
  ASSERT_EQ(scene.materials.size(), 3u);

  const Material& m = scene.materials[0];
  ASSERT_TRUE(m.base_color_texture.valid() && m.metallic_roughness_texture.valid());
  EXPECT_EQ(m.base_color, glm::vec4(1.0f));
  EXPECT_EQ(m.metallic, 1.0f);
  EXPECT_EQ(m.roughness, 1.0f);
  // The baked textures keep the mapping and the sampler.
  EXPECT_NEAR(m.base_color_texture.transform[2][0], 0.25f, 1e-6f);
  EXPECT_NEAR(m.metallic_roughness_texture.transform[2][0], 0.25f, 1e-6f);
  const Texture& base = scene.textures[m.base_color_texture.texture];
  const Texture& mr = scene.textures[m.metallic_roughness_texture.texture];
  ASSERT_EQ(base.width, 2);
  ASSERT_EQ(mr.height, 1);
  EXPECT_TRUE(base.nearest && mr.nearest);
  EXPECT_EQ(base.wrap_s, Wrap::ClampToEdge);
  // Texel 0: dielectric, base color = diffuse, roughness = 1 - 0.5 * 102/255.
  EXPECT_EQ(mr.texel(0).b, 0.0f);
  EXPECT_NEAR(mr.texel(0).g, 1.0f - 0.5f * 102 / 255.0f, 0.5f / 255 + 1e-6f);
  expect_vec3_near(base.texel(0), {linear_from_srgb(220 / 255.0f), linear_from_srgb(120 / 255.0f), linear_from_srgb(40 / 255.0f)}, 0.01f);
  // Texel 1: metal of the specular color.
  EXPECT_GT(mr.texel(1).b, 0.99f);
  EXPECT_NEAR(mr.texel(1).g, 1.0f - 0.5f * 230 / 255.0f, 0.5f / 255 + 1e-6f);
  expect_vec3_near(base.texel(1), {linear_from_srgb(250 / 255.0f), linear_from_srgb(210 / 255.0f), linear_from_srgb(130 / 255.0f)}, 0.01f);

  const Material& x = scene.materials[1];
  ASSERT_TRUE(x.base_color_texture.valid() && x.metallic_roughness_texture.valid());
  EXPECT_EQ(scene.textures[x.base_color_texture.texture].name, scene.textures[0].name);  // the diffuse texture itself
  EXPECT_GT(scene.textures[x.metallic_roughness_texture.texture].texel(1).b, 0.9f);

  std::string w;
  for (const std::string& line : scene.warnings)
    if (line.find("KHR_materials_pbrSpecularGlossiness") != std::string::npos) {
      EXPECT_TRUE(w.empty()) << warnings_of(scene);  // one line per file
      w = line;
    }
  EXPECT_NE(w.find("KHR_materials_pbrSpecularGlossiness"), std::string::npos) << w;
  EXPECT_NE(w.find("baked"), std::string::npos) << w;
  EXPECT_NE(w.find("approximated for 'mixed'"), std::string::npos) << w;
}

TEST(SceneLoadMaterial, AlphaMaskBlendAndDoubleSided) {
  std::string dir = temp_dir();
  GltfBuilder b;
  int mask = b.material({{"alphaMode", "MASK"}, {"alphaCutoff", 0.3}, {"doubleSided", true}});
  int blend = b.material({{"alphaMode", "BLEND"}});
  int opaque = b.material(json::object());
  b.scene({b.node({{"mesh", b.mesh(b.quad_primitive(mask))}}), b.node({{"mesh", b.mesh(b.quad_primitive(blend))}}),
           b.node({{"mesh", b.mesh(b.quad_primitive(opaque))}})});
  Scene scene = load_scene(b.write_gltf(dir + "/alpha.gltf"));
  EXPECT_EQ(scene.materials[0].alpha_mode, AlphaMode::Mask);
  EXPECT_FLOAT_EQ(scene.materials[0].alpha_cutoff, 0.3f);
  EXPECT_TRUE(scene.materials[0].double_sided);
  EXPECT_EQ(scene.materials[1].alpha_mode, AlphaMode::Blend);
  EXPECT_FALSE(scene.materials[1].double_sided);
  EXPECT_EQ(scene.materials[2].alpha_mode, AlphaMode::Opaque);
}

TEST(SceneLoadTexture, BaseColorIsSrgbDecodedAndMetallicRoughnessIsLinear) {
  std::string dir = temp_dir();
  GltfBuilder b;
  std::vector<uint8_t> png = encode_png(2, 1, 3, 8, {128, 255, 0, 0, 64, 255});
  write_bytes(dir + "/color.png", png);
  b.doc["images"].push_back({{"uri", "color.png"}});
  int tex = b.texture(0);
  int mat = b.material({{"pbrMetallicRoughness",
                         {{"baseColorFactor", {0.5, 1, 1, 1}},
                          {"baseColorTexture", {{"index", tex}}},
                          {"metallicRoughnessTexture", {{"index", tex}}}}}});
  b.add_quad_scene(mat);
  Scene scene = load_scene(b.write_gltf(dir + "/tex.gltf"));
  const Material& m = scene.materials[0];
  EXPECT_FLOAT_EQ(m.base_color.x, 0.5f);
  ASSERT_TRUE(m.base_color_texture.valid());
  ASSERT_TRUE(m.metallic_roughness_texture.valid());
  const Texture& color = scene.textures[m.base_color_texture.texture];
  const Texture& linear = scene.textures[m.metallic_roughness_texture.texture];
  ASSERT_EQ(color.width, 2);
  ASSERT_EQ(color.height, 1);
  EXPECT_NEAR(color.texel(0).x, linear_from_srgb(128 / 255.0f), 1e-6f);
  EXPECT_NEAR(color.texel(0).y, 1.0f, 1e-6f);
  EXPECT_EQ(color.texel(0).w, 1.0f);
  EXPECT_NEAR(linear.texel(1).y, 64 / 255.0f, 1e-6f);  // roughness channel as stored
  EXPECT_NEAR(eval_texture(scene, m.base_color_texture, {0.75f, 0.5f}, {}).z, 1.0f, 1e-6f);
  EXPECT_EQ(color.name, "color.png");
}

TEST(SceneLoadTexture, SixteenBitNonPowerOfTwoGrayTexture) {
  std::string dir = temp_dir();
  GltfBuilder b;
  std::vector<uint32_t> samples;
  for (int i = 0; i < 15; ++i) samples.push_back(i * 4000 + 7);
  int tex = b.texture(b.image(encode_png(3, 5, 1, 16, samples)));
  int mat = b.material({{"pbrMetallicRoughness", {{"metallicRoughnessTexture", {{"index", tex}}}}}});
  b.add_quad_scene(mat);
  Scene scene = load_scene(b.write_gltf(dir + "/t16.gltf"));
  const TextureRef& ref = scene.materials[0].metallic_roughness_texture;
  ASSERT_TRUE(ref.valid());
  const Texture& t = scene.textures[ref.texture];
  ASSERT_EQ(t.width, 3);
  ASSERT_EQ(t.height, 5);
  for (int i = 0; i < 15; ++i) {
    EXPECT_NEAR(t.texel(i).x, samples[i] / 65535.0f, 1e-7f) << i;
    EXPECT_EQ(t.texel(i).x, t.texel(i).z);
    EXPECT_EQ(t.texel(i).w, 1.0f);
  }
}

// 8-bit textures keep their codes; every lookup (nearest and bilinear, any wrap) returns exactly
// what a float texture holding the loader's former per-texel decoding returns: sRGB channels
// linear_from_srgb(k / 255), linear channels and alpha k / 255, gray expanded, missing alpha 1.
TEST(SceneLoadTexture, EightBitStorageLooksUpBitExactly) {
  std::string dir = temp_dir();
  uint32_t state = 12345;
  auto next = [&] {
    state = state * 1664525u + 1013904223u;
    return (state >> 24) & 255u;
  };
  for (int channels = 1; channels <= 4; ++channels) {
    const int w = 7, h = 5;
    std::vector<uint32_t> codes(static_cast<size_t>(w) * h * channels);
    for (uint32_t& c : codes) c = next();
    codes[0] = 0;
    codes[1 % codes.size()] = 255;
    GltfBuilder b;
    b.doc["samplers"] = {{{"wrapS", 33648}, {"wrapT", 10497}}};
    int tex = b.texture(b.image(encode_png(w, h, channels, 8, codes)), {{"sampler", 0}});
    int mat = b.material({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", tex}}}, {"metallicRoughnessTexture", {{"index", tex}}}}}});
    b.add_quad_scene(mat);
    Scene scene = load_scene(b.write_gltf(dir + "/t8_" + std::to_string(channels) + ".gltf"));
    for (bool srgb : {true, false}) {
      const Material& m = scene.materials[0];
      const TextureRef& ref = srgb ? m.base_color_texture : m.metallic_roughness_texture;
      ASSERT_TRUE(ref.valid()) << warnings_of(scene);
      const Texture& t = scene.textures[ref.texture];
      EXPECT_TRUE(t.is_8bit());
      EXPECT_EQ(t.memory_bytes(), static_cast<size_t>(w * h + 3 * 2 + 1) * 4);  // 7x5 and its mips 3x2, 1x1
      Texture reference = t;
      reference.texels8.reset();
      for (int i = 0; i < w * h; ++i) {
        const uint32_t* p = &codes[static_cast<size_t>(i) * channels];
        auto color = [&](uint32_t k) { return srgb ? linear_from_srgb(k / 255.0f) : k / 255.0f; };
        glm::vec4 v = channels <= 2 ? glm::vec4(color(p[0]), color(p[0]), color(p[0]), channels == 2 ? p[1] / 255.0f : 1.0f)
                                    : glm::vec4(color(p[0]), color(p[1]), color(p[2]), channels == 4 ? p[3] / 255.0f : 1.0f);
        reference.texels.push_back(v);
      }
      for (bool nearest : {false, true}) {
        Texture a = t, r = reference;
        a.nearest = r.nearest = nearest;
        for (int k = 0; k < 500; ++k) {
          glm::vec2 uv(next() / 64.0f - 1.5f + next() / 16384.0f, next() / 64.0f - 1.5f + next() / 16384.0f);
          glm::vec4 got = sample_texture(a, uv), want = sample_texture(r, uv);
          ASSERT_EQ(got, want) << channels << " channels, srgb " << srgb << ", uv " << uv.x << " " << uv.y;
        }
      }
    }
  }
}

TEST(SceneLoadTexture, GlbEmbeddedImageInBufferView) {
  std::string dir = temp_dir();
  GltfBuilder b;
  std::vector<uint8_t> png = encode_png(1, 2, 4, 8, {255, 0, 0, 255, 0, 0, 255, 128});
  int view = b.view(png.data(), png.size());
  b.doc["images"].push_back({{"bufferView", view}, {"mimeType", "image/png"}});
  int mat = b.material({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", b.texture(0)}}}}}});
  b.add_quad_scene(mat);
  Scene scene = load_scene(b.write_glb(dir + "/img.glb"));
  ASSERT_TRUE(scene.materials[0].base_color_texture.valid()) << warnings_of(scene);
  const Texture& t = scene.textures[scene.materials[0].base_color_texture.texture];
  EXPECT_EQ(t.texel(0), glm::vec4(1, 0, 0, 1));
  EXPECT_NEAR(t.texel(1).w, 128 / 255.0f, 1e-6f);  // alpha stays linear
}

TEST(SceneLoadTexture, SamplerWrapModesAndMagFilter) {
  std::string dir = temp_dir();
  GltfBuilder b;
  b.doc["samplers"] = {{{"wrapS", 33071}, {"wrapT", 33648}, {"magFilter", 9728}}};
  int tex = b.texture(b.image(encode_png(1, 1, 3, 8, {1, 2, 3})), {{"sampler", 0}});
  int plain = b.texture(0);
  int mat = b.material({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", tex}}}, {"metallicRoughnessTexture", {{"index", plain}}}}}});
  b.add_quad_scene(mat);
  Scene scene = load_scene(b.write_gltf(dir + "/sampler.gltf"));
  const Texture& t = scene.textures[scene.materials[0].base_color_texture.texture];
  EXPECT_EQ(t.wrap_s, Wrap::ClampToEdge);
  EXPECT_EQ(t.wrap_t, Wrap::MirroredRepeat);
  EXPECT_TRUE(t.nearest);
  const Texture& d = scene.textures[scene.materials[0].metallic_roughness_texture.texture];
  EXPECT_EQ(d.wrap_s, Wrap::Repeat);
  EXPECT_FALSE(d.nearest);
}

TEST(SceneLoadTexture, KhrTextureTransformAndTexcoordOverride) {
  std::string dir = temp_dir();
  GltfBuilder b;
  b.doc["extensionsUsed"] = {"KHR_texture_transform"};
  int tex = b.texture(b.image(encode_png(1, 1, 3, 8, {1, 2, 3})));
  json transform = {{"offset", {0.5, 0.0}}, {"rotation", 1.5707963}, {"scale", {2, 3}}, {"texCoord", 1}};
  int mat = b.material({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", tex}, {"extensions", {{"KHR_texture_transform", transform}}}}}}},
                        {"emissiveTexture", {{"index", tex}, {"texCoord", 1}}}});
  json prim = b.quad_primitive(mat);
  prim["attributes"]["TEXCOORD_1"] = b.floats({0, 0, 1, 0, 1, 1, 0, 1}, "VEC2");
  b.scene({b.node({{"mesh", b.mesh(prim)}})});
  // (Lit by the default sky: its only emission is textured, so --default-light none would warn.)
  Scene scene = load_scene(b.write_gltf(dir + "/tt.gltf"), "", 1.0f, DefaultLight::Sky);
  const TextureRef& ref = scene.materials[0].base_color_texture;
  ASSERT_TRUE(ref.valid());
  EXPECT_EQ(ref.texcoord, 1);
  glm::vec2 uv = texture_uv(ref, {0.3f, 0.3f}, {1.0f, 0.0f});
  EXPECT_NEAR(uv.x, 0.5f, 1e-5f);
  EXPECT_NEAR(uv.y, -2.0f, 1e-5f);
  const TextureRef& emissive = scene.materials[0].emissive_texture;
  EXPECT_EQ(emissive.texcoord, 1);
  EXPECT_EQ(emissive.transform, glm::mat3(1.0f));
  EXPECT_TRUE(scene.warnings.empty()) << warnings_of(scene);
}

// ----------------------------------------------------------------------------------------------
// Bad input

TEST(SceneLoadBadInput, MissingFileNamesIt) {
  std::string msg = error_of([] { load_scene("/nonexistent/dir/nothing.gltf"); });
  EXPECT_NE(msg.find("/nonexistent/dir/nothing.gltf"), std::string::npos) << msg;
}

TEST(SceneLoadBadInput, MalformedJson) {
  std::string dir = temp_dir();
  std::string path = dir + "/broken.gltf";
  std::ofstream(path) << "{ \"asset\": { \"version\": \"2.0\" }, \"nodes\": [ { \"mesh\": ";
  std::string msg = error_of([&] { load_scene(path); });
  EXPECT_EQ(msg.rfind(path, 0), 0u) << msg;
}

TEST(SceneLoadBadInput, TruncatedGlb) {
  std::string dir = temp_dir();
  GltfBuilder b;
  b.add_quad_scene();
  std::string path = b.write_glb(dir + "/cut.glb");
  fs::resize_file(path, fs::file_size(path) - 24);
  std::string msg = error_of([&] { load_scene(path); });
  EXPECT_EQ(msg.rfind(path, 0), 0u) << msg;
  // And a file that is only a header.
  fs::resize_file(path, 10);
  EXPECT_EQ(error_of([&] { load_scene(path); }).rfind(path, 0), 0u);
}

TEST(SceneLoadBadInput, OutOfRangeAccessorIndex) {
  std::string dir = temp_dir();
  GltfBuilder b;
  json prim = b.quad_primitive();
  prim["attributes"]["POSITION"] = 42;
  b.scene({b.node({{"mesh", b.mesh(prim)}})});
  std::string path = b.write_gltf(dir + "/acc.gltf");
  std::string msg = error_of([&] { load_scene(path); });
  EXPECT_EQ(msg.rfind(path, 0), 0u) << msg;
  EXPECT_NE(msg.find("accessor 42"), std::string::npos) << msg;
}

TEST(SceneLoadBadInput, OutOfRangeVertexIndex) {
  std::string dir = temp_dir();
  GltfBuilder b;
  json prim = b.quad_primitive();
  prim["indices"] = b.indices({0, 1, 7});
  b.scene({b.node({{"mesh", b.mesh(prim)}})});
  std::string path = b.write_gltf(dir + "/idx.gltf");
  std::string msg = error_of([&] { load_scene(path); });
  EXPECT_EQ(msg.rfind(path, 0), 0u) << msg;
  EXPECT_NE(msg.find("index 7 out of range"), std::string::npos) << msg;
}

TEST(SceneLoadBadInput, BufferViewPastTheEndOfItsBuffer) {
  std::string dir = temp_dir();
  GltfBuilder b;
  b.add_quad_scene();
  b.doc["bufferViews"][0]["byteLength"] = 4096;
  std::string path = b.write_gltf(dir + "/view.gltf");
  std::string msg = error_of([&] { load_scene(path); });
  EXPECT_EQ(msg.rfind(path, 0), 0u) << msg;
  // An accessor whose offset runs past its (valid) view.
  GltfBuilder c;
  c.add_quad_scene();
  c.doc["accessors"][0]["byteOffset"] = 40;
  std::string path2 = c.write_gltf(dir + "/offset.gltf");
  msg = error_of([&] { load_scene(path2); });
  EXPECT_NE(msg.find("past the end"), std::string::npos) << msg;
  // A GLB image in a bufferView that exceeds the buffer.
  GltfBuilder d;
  d.add_quad_scene(d.material({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}));
  d.doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 1 << 20}});
  d.doc["images"].push_back({{"bufferView", static_cast<int>(d.doc["bufferViews"].size()) - 1}, {"mimeType", "image/png"}});
  d.texture(0);
  std::string path3 = d.write_glb(dir + "/imgview.glb");
  EXPECT_EQ(error_of([&] { load_scene(path3); }).rfind(path3, 0), 0u);
}

TEST(SceneLoadBadInput, MissingBufferFile) {
  std::string dir = temp_dir();
  GltfBuilder b;
  b.add_quad_scene();
  json d = b.doc;
  d["buffers"] = json::array({{{"byteLength", b.bin.size()}, {"uri", "nothere.bin"}}});
  std::string path = dir + "/nobuf.gltf";
  std::ofstream(path) << d.dump();
  std::string msg = error_of([&] { load_scene(path); });
  EXPECT_EQ(msg.rfind(path, 0), 0u) << msg;
  EXPECT_NE(msg.find("nothere.bin"), std::string::npos) << msg;
}

TEST(SceneLoadBadInput, MissingTextureFileWarnsAndRendersWithout) {
  std::string dir = temp_dir();
  GltfBuilder b;
  b.doc["images"].push_back({{"uri", "lost_texture.png"}});
  int mat = b.material({{"pbrMetallicRoughness", {{"baseColorFactor", {0.2, 0.3, 0.4, 1}}, {"baseColorTexture", {{"index", b.texture(0)}}}}}});
  b.add_quad_scene(mat);
  Scene scene = load_scene(b.write_gltf(dir + "/lost.gltf"));
  EXPECT_FALSE(scene.materials[0].base_color_texture.valid());
  EXPECT_FLOAT_EQ(scene.materials[0].base_color.y, 0.3f);
  EXPECT_EQ(std::count_if(scene.warnings.begin(), scene.warnings.end(),
                          [](const std::string& w) { return w.find("lost_texture.png") != std::string::npos; }),
            1)
      << warnings_of(scene);
  EXPECT_EQ(scene.meshes.size(), 1u);
  // A corrupt image file warns the same way.
  write_bytes(dir + "/lost_texture.png", {0x89, 'P', 'N', 'G', 1, 2, 3});
  Scene again = load_scene(dir + "/lost.gltf");
  EXPECT_FALSE(again.materials[0].base_color_texture.valid());
  EXPECT_TRUE(any_warning_contains(again, "lost_texture.png")) << warnings_of(again);
}

TEST(SceneLoadBadInput, NanPositionsDropTheirTriangles) {
  std::string dir = temp_dir();
  GltfBuilder b;
  float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  json prim = {{"attributes", {{"POSITION", b.floats({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, nan, 0, 0, 0, inf, 0}, "VEC3")}}},
               {"indices", b.indices({0, 1, 2, 0, 2, 3, 4, 0, 1, 0, 5, 1, 4, 5, 0})}};
  b.scene({b.node({{"mesh", b.mesh(prim)}})});
  Scene scene = load_scene(b.write_gltf(dir + "/nan.gltf"));
  ASSERT_EQ(scene.meshes.size(), 1u);
  EXPECT_EQ(scene.meshes[0].triangles.size(), 2u);
  EXPECT_TRUE(any_warning_contains(scene, "dropped 3 triangles with NaN/Inf")) << warnings_of(scene);
  expect_scene_finite(scene);
}

TEST(SceneLoadBadInput, DegenerateTrianglesAreDroppedAndCounted) {
  std::string dir = temp_dir();
  GltfBuilder b;
  // A zero-area emitter: its only triangle is collinear, so the mesh disappears.
  int light = b.material({{"emissiveFactor", {1, 1, 1}}});
  json line = {{"attributes", {{"POSITION", b.floats({0, 0, 0, 1, 1, 1, 2, 2, 2}, "VEC3")}}}, {"material", light}};
  json quad = b.quad_primitive();
  quad["indices"] = b.indices({0, 1, 2, 0, 2, 3, 1, 1, 2});
  b.scene({b.node({{"mesh", b.mesh(line)}}), b.node({{"mesh", b.mesh(quad)}})});
  Scene scene = load_scene(b.write_gltf(dir + "/degenerate.gltf"));
  ASSERT_EQ(scene.meshes.size(), 1u);
  EXPECT_EQ(scene.meshes[0].triangles.size(), 2u);
  EXPECT_TRUE(any_warning_contains(scene, "dropped 2 degenerate")) << warnings_of(scene);
}

TEST(SceneLoadBadInput, UnsupportedExtensions) {
  std::string dir = temp_dir();
  GltfBuilder b;
  b.add_quad_scene();
  b.doc["extensionsUsed"] = {"EXT_made_up_compression", "EXT_made_up", "KHR_texture_transform"};
  b.doc["extensionsRequired"] = {"EXT_made_up_compression"};
  std::string path = b.write_gltf(dir + "/req.gltf");
  std::string msg = error_of([&] { load_scene(path); });
  EXPECT_EQ(msg.rfind(path, 0), 0u) << msg;
  EXPECT_NE(msg.find("EXT_made_up_compression"), std::string::npos) << msg;

  b.doc["extensionsRequired"] = {"KHR_texture_transform"};
  Scene scene = load_scene(b.write_gltf(dir + "/used.gltf"));
  size_t lines = 0;
  for (const std::string& w : scene.warnings)
    if (w.find("EXT_made_up") != std::string::npos) {
      ++lines;
      EXPECT_NE(w.find("EXT_made_up_compression"), std::string::npos) << w;
      EXPECT_EQ(w.find("KHR_texture_transform"), std::string::npos) << w;
    }
  EXPECT_EQ(lines, 1u) << warnings_of(scene);
  EXPECT_EQ(scene.meshes.size(), 1u);
}

TEST(SceneLoadBadInput, NodeCycleAndBadMaterialIndex) {
  std::string dir = temp_dir();
  GltfBuilder b;
  b.doc["nodes"] = {{{"children", {1}}}, {{"children", {0}}}};
  b.doc["scenes"] = {{{"nodes", {0}}}};
  std::string path = b.write_gltf(dir + "/cycle.gltf");
  std::string msg = error_of([&] { load_scene(path); });
  EXPECT_EQ(msg.rfind(path, 0), 0u) << msg;

  GltfBuilder c;
  c.add_quad_scene(5);
  std::string path2 = c.write_gltf(dir + "/mat.gltf");
  EXPECT_NE(error_of([&] { load_scene(path2); }).find("material 5"), std::string::npos);
}

// ----------------------------------------------------------------------------------------------
// Hostile input

TEST(SceneLoadBadInput, DeepNodeHierarchyLoadsWithoutOverflowingTheStack) {
  // Far deeper than the ~8,400 levels a recursive traversal survived in Release.
  std::string dir = temp_dir();
  GltfBuilder b;
  const int depth = 30000;
  b.doc["nodes"] = json::array();
  for (int i = 0; i < depth; ++i) {
    json n = {{"translation", {0.0, 0.0, 1e-6}}};
    if (i + 1 < depth) n["children"] = {i + 1};
    b.doc["nodes"].push_back(n);
  }
  b.doc["nodes"][depth - 1]["mesh"] = b.mesh(b.quad_primitive());
  b.doc["scenes"] = {{{"nodes", {0}}}};
  Scene scene = load_scene(b.write_gltf(dir + "/deep.gltf"));
  ASSERT_EQ(scene.meshes.size(), 1u);
  EXPECT_NEAR(scene.meshes[0].positions[0].z, depth * 1e-6f, 1e-3f);

  // A cycle at the bottom of a deep chain is still found and named.
  b.doc["nodes"][depth - 1]["children"] = {depth / 2};
  std::string cyclic = b.write_gltf(dir + "/deep_cycle.gltf");
  EXPECT_NE(error_of([&] { load_scene(cyclic); }).find("cycle"), std::string::npos);
}

TEST(SceneLoadBadInput, HugeWorldCoordinatesAreRefusedWithTheLimit) {
  std::string dir = temp_dir();
  auto load_with = [&](const json& node_extra, const std::string& name) {
    GltfBuilder b;
    json n = {{"mesh", b.mesh(b.quad_primitive())}};
    n.update(node_extra);
    b.scene({b.node(n)});
    return b.write_gltf(dir + "/" + name);
  };
  std::string far_mesh = load_with({{"translation", {0, 0, 3.4e38}}}, "far_mesh.gltf");
  std::string msg = error_of([&] { load_scene(far_mesh); });
  EXPECT_EQ(msg.rfind(far_mesh, 0), 0u) << msg;
  EXPECT_NE(msg.find("3.4e+38"), std::string::npos) << msg;
  EXPECT_NE(msg.find("1e+12"), std::string::npos) << msg;

  GltfBuilder c;
  c.doc["cameras"] = {{{"type", "perspective"}, {"perspective", {{"yfov", 0.8}, {"znear", 0.1}}}}};
  c.scene({c.node({{"mesh", c.mesh(c.quad_primitive())}}), c.node({{"camera", 0}, {"translation", {0, 0, 1e20}}})});
  std::string far_camera = c.write_gltf(dir + "/far_camera.gltf");
  EXPECT_NE(error_of([&] { load_scene(far_camera); }).find("camera 0"), std::string::npos);

  // Large but representable scenes still load.
  EXPECT_EQ(load_scene(load_with({{"translation", {0, 0, 1e11}}}, "near.gltf")).meshes.size(), 1u);
}

TEST(SceneLoadGeometry, DegenerateTriangleTestIsScaleInvariant) {
  // Well-shaped triangles at 1e-12 and 1e11 units: float cross products underflow or overflow there.
  std::string dir = temp_dir();
  for (double scale : {1e-12, 1e-10, 1.0, 1e9, 1e11}) {
    GltfBuilder b;
    b.scene({b.node({{"mesh", b.mesh(b.quad_primitive())}, {"scale", {scale, scale, scale}}})});
    Scene scene = load_scene(b.write_gltf(dir + "/scaled.gltf"));
    ASSERT_EQ(scene.meshes.size(), 1u) << scale << "\n" << warnings_of(scene);
    EXPECT_EQ(scene.meshes[0].triangles.size(), 2u) << scale;
    EXPECT_FALSE(any_warning_contains(scene, "degenerate")) << scale << "\n" << warnings_of(scene);
  }
}

TEST(SceneLoadBadInput, AbsoluteUrisWorkWhateverTheScenePath) {
  std::string dir = fs::absolute(temp_dir()).string();
  GltfBuilder b;
  b.add_quad_scene();
  write_bytes(dir + "/data.bin", b.bin);
  json d = b.doc;
  d["buffers"] = json::array({{{"byteLength", b.bin.size()}, {"uri", dir + "/data.bin"}}});
  fs::create_directories(dir + "/sub");
  std::ofstream(dir + "/sub/abs.gltf") << d.dump();
  EXPECT_EQ(load_scene(dir + "/sub/abs.gltf").meshes.size(), 1u);
  // Relative uris still resolve against the glTF's folder, not the working directory.
  d["buffers"][0]["uri"] = "../data.bin";
  std::ofstream(dir + "/sub/rel.gltf") << d.dump();
  EXPECT_EQ(load_scene(dir + "/sub/rel.gltf").meshes.size(), 1u);
}

TEST(SceneLoadBadInput, FromMemoryMatchesFromFile) {
  std::string dir = temp_dir();
  GltfBuilder b;
  b.add_quad_scene();
  std::string path = b.write_glb(dir + "/quad.glb");
  std::ifstream in(path, std::ios::binary);
  std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  Scene scene = load_scene_from_memory(bytes, "memory.glb", dir);
  ASSERT_EQ(scene.meshes.size(), 1u);
  EXPECT_EQ(scene.meshes[0].triangles.size(), 2u);
  bytes.resize(bytes.size() / 2);
  EXPECT_EQ(error_of([&] { load_scene_from_memory(bytes, "memory.glb", dir); }).rfind("memory.glb: ", 0), 0u);
}

// ----------------------------------------------------------------------------------------------
// Environment and built-in scenes

TEST(SceneLoadEnvironment, ExrIsSanitizedAndWrapsHorizontally) {
  std::string dir = temp_dir();
  GltfBuilder b;
  b.add_quad_scene();
  std::string scene_path = b.write_gltf(dir + "/env.gltf");
  Image env = Image::rgb(4, 2, 0.5f);
  env.at(0, 0, 0) = std::numeric_limits<float>::quiet_NaN();
  env.at(1, 0, 1) = std::numeric_limits<float>::infinity();
  env.at(2, 1, 2) = -3.0f;
  env.at(3, 1, 0) = 7.0f;
  std::string env_path = dir + "/sky.exr";
  write_exr(env_path, env);
  Scene scene = load_scene(scene_path, env_path, 2.5f);
  ASSERT_TRUE(scene.environment.has_value());
  const Environment& e = *scene.environment;
  EXPECT_FLOAT_EQ(e.strength, 2.5f);
  EXPECT_EQ(e.source, env_path);
  ASSERT_EQ(e.image.width, 4);
  ASSERT_EQ(e.image.height, 2);
  EXPECT_EQ(e.image.wrap_s, Wrap::Repeat);
  EXPECT_EQ(e.image.wrap_t, Wrap::ClampToEdge);
  EXPECT_EQ(e.image.texels[0], glm::vec4(0, 0.5f, 0.5f, 1));
  EXPECT_EQ(e.image.texels[1].y, 0.0f);
  EXPECT_EQ(e.image.texels[6].z, 0.0f);
  EXPECT_EQ(e.image.texels[7].x, 7.0f);
  EXPECT_TRUE(any_warning_contains(scene, "replaced 3 ")) << warnings_of(scene);
  // Without env_path there is no environment; a missing EXR is an error naming it.
  EXPECT_FALSE(load_scene(scene_path).environment.has_value());
  std::string msg = error_of([&] { load_scene(scene_path, dir + "/no_sky.exr"); });
  EXPECT_NE(msg.find("no_sky.exr"), std::string::npos) << msg;
}

// A tiny uncompressed Radiance .hdr (RGBE pixels; flat scanlines, as width < 8 is never RLE).
void write_radiance_hdr(const std::string& path, int w, int h, const std::vector<std::array<uint8_t, 4>>& rgbe) {
  std::string header = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y " + std::to_string(h) + " +X " + std::to_string(w) + "\n";
  std::vector<uint8_t> bytes(header.begin(), header.end());
  for (const auto& p : rgbe) bytes.insert(bytes.end(), p.begin(), p.end());
  write_bytes(path, bytes);
}

TEST(SceneLoadEnvironment, RadianceHdrIsReadByItsMagicBytes) {
  std::string dir = temp_dir();
  GltfBuilder b;
  b.add_quad_scene();
  std::string scene_path = b.write_gltf(dir + "/scene.gltf");
  // RGBE (128, 64, 192, 129): mantissa / 256 * 2^(129 - 128) = (1, 0.5, 1.5).
  std::vector<std::array<uint8_t, 4>> pixels(8, {128, 64, 192, 129});
  pixels[5] = {0, 0, 0, 0};
  std::string path = dir + "/sky.pic";  // the extension does not matter, the bytes do
  write_radiance_hdr(path, 4, 2, pixels);
  Scene scene = load_scene(scene_path, path, 1.0f);
  ASSERT_TRUE(scene.environment.has_value()) << warnings_of(scene);
  const Texture& t = scene.environment->image;
  ASSERT_EQ(t.width, 4);
  ASSERT_EQ(t.height, 2);
  expect_vec3_near(glm::vec3(t.texels[0]), {1.0f, 0.5f, 1.5f});
  expect_vec3_near(glm::vec3(t.texels[5]), {0.0f, 0.0f, 0.0f});
  EXPECT_TRUE(scene.warnings.empty()) << warnings_of(scene);
}

TEST(SceneLoadEnvironment, BadMapsFailBeforeTheSceneLoadsWithOneLine) {
  std::string dir = temp_dir();
  GltfBuilder b;
  b.add_quad_scene();
  std::string scene_path = b.write_gltf(dir + "/scene.gltf");
  // Not an environment format: the error lists the supported ones.
  std::string png_path = dir + "/sky.png";
  write_bytes(png_path, encode_png(2, 1, 3, 8, {255, 255, 255, 0, 0, 0}));
  std::string msg = error_of([&] { load_scene(scene_path, png_path); });
  EXPECT_NE(msg.find("OpenEXR"), std::string::npos) << msg;
  EXPECT_NE(msg.find("Radiance"), std::string::npos) << msg;
  // The environment is checked first: with a bad scene too, the message names the environment.
  msg = error_of([&] { load_scene(dir + "/missing.gltf", png_path); });
  EXPECT_NE(msg.find("sky.png"), std::string::npos) << msg;
  // No positive radiance anywhere is an error, not a black render.
  Image negative = Image::rgb(4, 2, -1.0f);
  write_exr(dir + "/negative.exr", negative);
  msg = error_of([&] { load_scene(scene_path, dir + "/negative.exr"); });
  EXPECT_NE(msg.find("no positive radiance"), std::string::npos) << msg;
  write_radiance_hdr(dir + "/black.hdr", 4, 2, std::vector<std::array<uint8_t, 4>>(8, {0, 0, 0, 0}));
  msg = error_of([&] { load_scene(scene_path, dir + "/black.hdr"); });
  EXPECT_NE(msg.find("no positive radiance"), std::string::npos) << msg;
}

TEST(SceneLoadEnvironment, NonTwoToOneMapWarnsAboutTheLatLongAssumption) {
  std::string dir = temp_dir();
  GltfBuilder b;
  b.add_quad_scene();
  std::string scene_path = b.write_gltf(dir + "/scene.gltf");
  write_exr(dir + "/square.exr", Image::rgb(4, 4, 1.0f));
  Scene scene = load_scene(scene_path, dir + "/square.exr");
  EXPECT_TRUE(scene.environment.has_value());
  EXPECT_TRUE(any_warning_contains(scene, "not 2:1")) << warnings_of(scene);
  EXPECT_TRUE(any_warning_contains(scene, "latitude-longitude")) << warnings_of(scene);
  write_exr(dir + "/wide.exr", Image::rgb(4, 2, 1.0f));
  EXPECT_FALSE(any_warning_contains(load_scene(scene_path, dir + "/wide.exr"), "not 2:1"));
}

TEST(SceneLoadEnvironment, ImagePassedAsTheSceneIsNamedAsSuch) {
  std::string dir = temp_dir();
  write_exr(dir + "/sky.exr", Image::rgb(4, 2, 1.0f));
  std::string msg = error_of([&] { load_scene(dir + "/sky.exr"); });
  EXPECT_NE(msg.find("environment image, not a scene"), std::string::npos) << msg;
  EXPECT_NE(msg.find("--env"), std::string::npos) << msg;
  write_radiance_hdr(dir + "/sky.hdr", 2, 1, std::vector<std::array<uint8_t, 4>>(2, {128, 128, 128, 129}));
  msg = error_of([&] { load_scene(dir + "/sky.hdr"); });
  EXPECT_NE(msg.find("environment image, not a scene"), std::string::npos) << msg;
}

TEST(SceneLoadMaterial, KhrMaterialsVolumeGivesTheBeerLambertCoefficient) {
  std::string dir = temp_dir();
  GltfBuilder b;
  b.doc["extensionsUsed"] = {"KHR_materials_transmission", "KHR_materials_volume"};
  auto volume = [&](json v) {
    return b.material({{"extensions", {{"KHR_materials_transmission", {{"transmissionFactor", 1.0}}}, {"KHR_materials_volume", v}}}});
  };
  int absorbing = volume({{"thicknessFactor", 1.0}, {"attenuationDistance", 0.5}, {"attenuationColor", {0.5, 0.25, 1.0}}});
  int thin = volume({{"thicknessFactor", 0.0}, {"attenuationDistance", 0.5}, {"attenuationColor", {0.5, 0.25, 1.0}}});
  int clear = volume({{"thicknessFactor", 1.0}, {"attenuationColor", {0.5, 0.25, 1.0}}});  // distance: infinite
  b.scene({b.node({{"mesh", b.mesh(b.quad_primitive(absorbing))}}), b.node({{"mesh", b.mesh(b.quad_primitive(thin))}}),
           b.node({{"mesh", b.mesh(b.quad_primitive(clear))}})});
  Scene scene = load_scene(b.write_gltf(dir + "/volume.gltf"));
  // After attenuationDistance the light left is attenuationColor: exp(-sigma 0.5) = color.
  expect_vec3_near(scene.materials[absorbing].attenuation, -glm::log(glm::vec3(0.5f, 0.25f, 1.0f)) / 0.5f);
  EXPECT_FALSE(scene.materials[thin].has_volume());
  EXPECT_FALSE(scene.materials[clear].has_volume());
  EXPECT_FALSE(any_warning_contains(scene, "KHR_materials_volume")) << warnings_of(scene);
}

TEST(SceneLoadMaterial, KhrMaterialsSheenReadsItsFactorsAndTextures) {
  std::string dir = temp_dir();
  GltfBuilder b;
  b.doc["extensionsUsed"] = {"KHR_materials_sheen"};
  const int white = b.texture(b.image(encode_png(1, 1, 4, 8, {255, 255, 255, 255})));
  const int velvet = b.material({{"extensions",
                                  {{"KHR_materials_sheen",
                                    {{"sheenColorFactor", {0.9, 0.5, 0.25}},
                                     {"sheenColorTexture", {{"index", white}}},
                                     {"sheenRoughnessFactor", 0.4},
                                     {"sheenRoughnessTexture", {{"index", white}}}}}}}});
  b.add_quad_scene(velvet);
  Scene scene = load_scene(b.write_gltf(dir + "/sheen.gltf"));
  EXPECT_FALSE(any_warning_contains(scene, "sheen")) << warnings_of(scene);
  const Material& m = scene.materials[velvet];
  expect_vec3_near(m.sheen_color, {0.9f, 0.5f, 0.25f});
  EXPECT_FLOAT_EQ(m.sheen_roughness, 0.4f);
  EXPECT_TRUE(m.sheen_color_texture.valid() && m.sheen_roughness_texture.valid());
}

TEST(SceneLoadMaterial, KhrMaterialsClearcoatReadsItsFactorsTexturesAndNormalMap) {
  std::string dir = temp_dir();
  GltfBuilder b;
  b.doc["extensionsUsed"] = {"KHR_materials_clearcoat"};
  const int grey = b.texture(b.image(encode_png(1, 1, 3, 8, {128, 128, 128})));
  // A normal map tilted towards +T (tangent +X on this quad): n = normalize(T + N) at scale 1.
  const int tilted = b.texture(b.image(encode_png(1, 1, 3, 8, {255, 128, 255})));
  const int coated = b.material({{"extensions",
                                  {{"KHR_materials_clearcoat",
                                    {{"clearcoatFactor", 0.8},
                                     {"clearcoatTexture", {{"index", grey}}},
                                     {"clearcoatRoughnessFactor", 0.3},
                                     {"clearcoatRoughnessTexture", {{"index", grey}}},
                                     {"clearcoatNormalTexture", {{"index", tilted}, {"scale", 1.0}}}}}}}});
  b.add_quad_scene(coated);
  Scene scene = load_scene(b.write_gltf(dir + "/coat.gltf"));
  EXPECT_FALSE(any_warning_contains(scene, "clearcoat")) << warnings_of(scene);
  const Material& m = scene.materials[coated];
  EXPECT_FLOAT_EQ(m.clearcoat, 0.8f);
  EXPECT_FLOAT_EQ(m.clearcoat_roughness, 0.3f);
  EXPECT_TRUE(m.clearcoat_texture.valid() && m.clearcoat_roughness_texture.valid() && m.clearcoat_normal_texture.valid());
  EXPECT_FLOAT_EQ(m.clearcoat_normal_scale, 1.0f);
  ASSERT_EQ(scene.meshes[0].tangents.size(), scene.meshes[0].positions.size());  // for the coat's normal map
}

// ----------------------------------------------------------------------------------------------
// Default light

TEST(SceneLoadDefaultLight, NoneKeepsTheSceneDarkAndWarns) {
  std::string dir = temp_dir();
  GltfBuilder b;
  b.add_quad_scene();
  std::string path = b.write_gltf(dir + "/bare.gltf");
  Scene scene = load_scene(path, "", 1.0f, DefaultLight::None);
  EXPECT_FALSE(scene.environment.has_value());
  EXPECT_TRUE(scene.notes.empty());
  EXPECT_TRUE(any_warning_contains(scene, "will be black")) << warnings_of(scene);
}

TEST(SceneLoadDefaultLight, OnlyScenesWithoutAnyLightGetIt) {
  std::string dir = temp_dir();
  // A uniform emitter is a light: no default environment.
  GltfBuilder lamp;
  lamp.add_quad_scene(lamp.material({{"emissiveFactor", {1.0, 1.0, 1.0}}}));
  Scene lit = load_scene(lamp.write_gltf(dir + "/lamp.gltf"), "", 1.0f, DefaultLight::Sky);
  EXPECT_FALSE(lit.environment.has_value());
  EXPECT_TRUE(lit.notes.empty());
  // Texture-modulated emission (a helmet's LEDs) lights nothing around it: the default applies.
  GltfBuilder leds;
  int texture = leds.texture(leds.image(encode_png(1, 1, 3, 8, {255, 0, 0})));
  leds.add_quad_scene(leds.material({{"emissiveFactor", {1.0, 1.0, 1.0}}, {"emissiveTexture", {{"index", texture}}}}));
  Scene decorated = load_scene(leds.write_gltf(dir + "/leds.gltf"), "", 1.0f, DefaultLight::Sky);
  EXPECT_TRUE(decorated.environment.has_value());
  // An --env wins over the default.
  write_exr(dir + "/env.exr", Image::rgb(4, 2, 0.25f));
  GltfBuilder bare;
  bare.add_quad_scene();
  Scene with_env = load_scene(bare.write_gltf(dir + "/bare.gltf"), dir + "/env.exr", 1.0f, DefaultLight::Studio);
  ASSERT_TRUE(with_env.environment.has_value());
  EXPECT_EQ(with_env.environment->source, dir + "/env.exr");
}

// The built-in environments are neutral light of a sensible scale: an upward white Lambert
// surface sees an irradiance of order pi, and neither is a coloured cast.
TEST(SceneLoadDefaultLight, BuiltInEnvironmentsGiveAboutPiIrradianceFromAbove) {
  for (DefaultLight light : {DefaultLight::Sky, DefaultLight::Studio}) {
    Environment env = make_default_environment(light);
    const Texture& t = env.image;
    ASSERT_EQ(t.width, 2 * t.height);
    glm::dvec3 irradiance(0.0);
    const double pi = 3.14159265358979;
    for (int y = 0; y < t.height; ++y) {
      double theta = (y + 0.5) / t.height * pi;
      double solid_angle = (2 * pi / t.width) * (pi / t.height) * std::sin(theta);
      double cos_up = std::cos(theta);
      if (cos_up <= 0) continue;
      for (int x = 0; x < t.width; ++x) irradiance += glm::dvec3(glm::vec3(t.texels[static_cast<size_t>(y) * t.width + x])) * cos_up * solid_angle;
    }
    double e = (irradiance.x + irradiance.y + irradiance.z) / 3.0;
    EXPECT_GT(e, 0.5 * pi) << default_light_name(light);
    EXPECT_LT(e, 2.0 * pi) << default_light_name(light);
    EXPECT_LT(std::max({irradiance.x, irradiance.y, irradiance.z}) / std::min({irradiance.x, irradiance.y, irradiance.z}), 1.25)
        << default_light_name(light);
  }
}

TEST(SceneLoadBuiltin, ListsOnlyExistingScenesAndLoadsThemByName) {
  std::vector<BuiltinScene> scenes = builtin_scenes();
  for (const BuiltinScene& s : scenes) {
    EXPECT_TRUE(fs::is_regular_file(s.path)) << s.path;
    EXPECT_FALSE(s.description.empty());
    EXPECT_EQ(fs::path(s.path).filename().string(), s.name + ".gltf");
  }
  auto cornell = std::find_if(scenes.begin(), scenes.end(), [](const BuiltinScene& s) { return s.name == "cornell"; });
  if (cornell == scenes.end()) GTEST_SKIP() << "assets/cornell not generated yet";
  auto start = std::chrono::steady_clock::now();
  Scene scene = load_scene("cornell");
  double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  std::cout << "cornell: " << scene.triangle_count() << " triangles, " << scene.materials.size() << " materials, loaded in "
            << ms << " ms\n";
  EXPECT_EQ(scene.source, "cornell");
  EXPECT_GT(scene.triangle_count(), 0u);
  bool emissive = false;
  for (const Mesh& m : scene.meshes) emissive |= scene.materials[m.material].is_emissive();
  EXPECT_TRUE(emissive || !scene.lights.empty());
  expect_scene_finite(scene);
  for (const std::string& w : scene.warnings) ADD_FAILURE() << "built-in scene warning: " << w;
}

// ---------------------------------------------------------------------------------------------
// Resource limits

// A PNG whose header declares `w` x `h` but that holds no pixel data: a small file asking for a
// huge decode.
std::vector<uint8_t> png_header_only(uint32_t w, uint32_t h) {
  std::vector<uint8_t> png = encode_png(1, 1, 3, 8, {1, 2, 3});
  // IHDR data starts after the 8-byte signature, the chunk length and type (16..23: width, height).
  for (int i = 0; i < 4; ++i) {
    png[16 + i] = static_cast<uint8_t>(w >> (24 - 8 * i));
    png[20 + i] = static_cast<uint8_t>(h >> (24 - 8 * i));
  }
  return png;
}

TEST(SceneLoadLimits, TextureOverTheSizeCapIsAClearErrorAndTheOverrideLoadsIt) {
  std::string dir = temp_dir();
  GltfBuilder b;
  std::vector<uint8_t> png = png_header_only(20000, 20000);
  int view = b.view(png.data(), png.size());
  b.doc["images"].push_back({{"bufferView", view}, {"mimeType", "image/png"}, {"name", "huge"}});
  b.add_quad_scene(b.material({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", b.texture(0)}}}}}}));
  const std::string path = b.write_glb(dir + "/huge_texture.glb");
  std::string msg = error_of([&] { load_scene(path); });
  EXPECT_EQ(msg.rfind(path + ": ", 0), 0u) << msg;
  EXPECT_NE(msg.find("image 0 'huge' is 20000x20000, over the texture size limit of 16384 (raise it with --max-texture-size)"),
            std::string::npos) << msg;
  // Raised: the header passes; the (missing) pixel data then costs only the texture, with a warning.
  LoadLimits limits;
  limits.max_texture_size = 20000;
  limits.available_memory = uint64_t(1) << 50;
  Scene scene = load_scene(path, "", 1.0f, DefaultLight::None, limits);
  EXPECT_FALSE(scene.materials[0].base_color_texture.valid());
  EXPECT_TRUE(any_warning_contains(scene, "could not be loaded")) << warnings_of(scene);

  // A real texture one texel over the cap, then exactly at it.
  GltfBuilder small;
  std::vector<uint32_t> codes(9 * 4 * 3, 200);
  small.add_quad_scene(small.material({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", small.texture(small.image(encode_png(9, 4, 3, 8, codes)))}}}}}}));
  const std::string small_path = small.write_gltf(dir + "/nine.gltf");
  limits.max_texture_size = 8;
  EXPECT_NE(error_of([&] { load_scene(small_path, "", 1.0f, DefaultLight::None, limits); }).find("is 9x4, over the texture size limit of 8"),
            std::string::npos);
  limits.max_texture_size = 9;
  Scene nine = load_scene(small_path, "", 1.0f, DefaultLight::None, limits);
  ASSERT_TRUE(nine.materials[0].base_color_texture.valid());
  EXPECT_EQ(nine.textures[nine.materials[0].base_color_texture.texture].width, 9);
}

TEST(SceneLoadLimits, EstimateOverTheAvailableMemoryIsRefusedBeforeAllocating) {
  std::string dir = temp_dir();
  GltfBuilder b;
  // 4096 x 4096 declared (64 MiB as RGBA8), a few hundred bytes in the file.
  std::vector<uint8_t> png = png_header_only(4096, 4096);
  int view = b.view(png.data(), png.size());
  b.doc["images"].push_back({{"bufferView", view}, {"mimeType", "image/png"}});
  b.add_quad_scene(b.material({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", b.texture(0)}}}}}}));
  const std::string path = b.write_glb(dir + "/big.glb");
  LoadLimits limits;
  limits.available_memory = 100ull << 20;  // 100 MiB
  std::string msg = error_of([&] { load_scene(path, "", 1.0f, DefaultLight::None, limits); });
  EXPECT_EQ(msg.rfind(path + ": ", 0), 0u) << msg;
  // 64 MiB stored + 21.3 MiB of mips + 64 MiB raster copy + 128 MiB decoding, and a quad.
  EXPECT_NE(msg.find("loading needs an estimated 277 MiB (2 triangles, 64 MiB of textures), more than the 100 MiB of memory available"),
            std::string::npos) << msg;
  limits.available_memory = 300ull << 20;
  EXPECT_NO_THROW(load_scene(path, "", 1.0f, DefaultLight::None, limits));
  // The estimate itself, by its documented parts.
  LoadEstimate e;
  e.vertices = 4;
  e.triangles = 2;
  e.texture_bytes = 1000;
  e.largest_decode_bytes = 500;
  EXPECT_EQ(e.bytes(), 4u * 200 + 2u * (136 + 768) + 2u * 1000 + 1000u / 3 + 500);  // texels stored, copied, mipped
  e.triangles = UINT64_MAX / 2;
  EXPECT_EQ(e.bytes(), UINT64_MAX);  // saturates rather than wrapping
  EXPECT_GT(available_memory_bytes(), 0u);
}

TEST(SceneLoadLimits, InstancedTrianglesOverTheCapAreAClearError) {
  std::string dir = temp_dir();
  GltfBuilder b;
  int mesh = b.mesh(b.quad_primitive());
  std::vector<int> roots;
  for (int i = 0; i < 10; ++i) roots.push_back(b.node({{"mesh", mesh}, {"translation", {i * 2.0, 0, 0}}}));
  b.scene(roots);
  const std::string path = b.write_gltf(dir + "/ten.gltf");
  LoadLimits limits;
  limits.max_triangles = 19;
  std::string msg = error_of([&] { load_scene(path, "", 1.0f, DefaultLight::None, limits); });
  EXPECT_NE(msg.find("the scene instances 20 triangles, over the limit of 19 (raise it with --max-triangles)"), std::string::npos) << msg;
  limits.max_triangles = 20;
  EXPECT_EQ(load_scene(path, "", 1.0f, DefaultLight::None, limits).triangle_count(), 20u);

  // 64 levels, each node referencing the next twice: 2^64 instances, counted without walking them.
  GltfBuilder d;
  int leaf = d.node({{"mesh", d.mesh(d.quad_primitive())}});
  int next = leaf;
  for (int level = 0; level < 64; ++level) next = d.node({{"children", {next, next}}});
  d.scene({next});
  const std::string deep = d.write_gltf(dir + "/doubling.gltf");
  msg = error_of([&] { load_scene(deep); });
  EXPECT_NE(msg.find("the scene instances more than 1.8e19 triangles, over the limit of 100000000"), std::string::npos) << msg;
}


// ----------------------------------------------------------------------------------------------
// Hostile input at the limits: camera-derived ray origins, JSON depth, texture transforms, the whole memory estimate

// A quad seen by a camera node with `camera_node`'s transform (a perspective camera unless `camera` says).
std::string write_camera_scene(const std::string& path, const json& camera_node, const json& camera = nullptr) {
  GltfBuilder b;
  b.doc["cameras"] = json::array({camera.is_null() ? json{{"type", "perspective"}, {"perspective", {{"yfov", 0.8}, {"znear", 0.01}}}}
                                                   : camera});
  json node = camera_node;
  node["camera"] = 0;
  b.scene({b.node({{"mesh", b.mesh(b.quad_primitive())}}), b.node(node)});
  return b.write_gltf(path);
}

TEST(SceneLoadLimits, CameraScaledBeyondFloatLengthsKeepsAUnitFrame) {
  const std::string dir = temp_dir();
  // |column|^2 = 4e38 overflows float: normalizing by it gave a zero basis (NaN rays, an Embree abort).
  const Scene scene = load_scene(write_camera_scene(dir + "/scaled.gltf", {{"translation", {0, 0, 3}}, {"scale", {2e19, 2e19, 2e19}}}));
  const glm::mat3 basis(scene.camera.camera_to_world);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(glm::length(basis[c]), 1.0f, 1e-5f) << "column " << c;
  expect_vec3_near(glm::vec3(scene.camera.camera_to_world[3]), glm::vec3(0, 0, 3));
  const Ray ray = camera_ray(scene.camera, 16, 16, 3.0f, 5.0f);
  EXPECT_TRUE(std::isfinite(ray.direction.x) && std::isfinite(ray.direction.y) && std::isfinite(ray.direction.z));
  // A camera placed far out is the coordinate bound's.
  const std::string msg = error_of([&] { load_scene(write_camera_scene(dir + "/far.gltf", {{"translation", {0, 0, 3e12}}})); });
  EXPECT_NE(msg.find("camera 0 has a world-space coordinate of 3e+12, beyond the supported 1e+12"), std::string::npos) << msg;
}

TEST(SceneLoadLimits, OrthographicExtentBeyondTheCoordinateBoundIsRefused) {
  const std::string dir = temp_dir();
  auto ortho = [](double xmag, double ymag) {
    return json{{"type", "orthographic"}, {"orthographic", {{"xmag", xmag}, {"ymag", ymag}, {"znear", 0.01}, {"zfar", 100}}}};
  };
  const json at = {{"translation", {0, 0, 3}}};
  std::string msg = error_of([&] { load_scene(write_camera_scene(dir + "/y.gltf", at, ortho(1, 1e19))); });
  EXPECT_NE(msg.find("y.gltf: orthographic camera 0 ymag is 1e+19, beyond the supported 1e+12"), std::string::npos) << msg;
  msg = error_of([&] { load_scene(write_camera_scene(dir + "/x.gltf", at, ortho(1e19, 1))); });
  EXPECT_NE(msg.find("orthographic camera 0 xmag is 1e+19"), std::string::npos) << msg;
  EXPECT_FLOAT_EQ(load_scene(write_camera_scene(dir + "/ok.gltf", at, ortho(1e6, 1e6))).camera.ymag, 1e6f);
}

std::string nested_arrays(size_t depth) { return std::string(depth, '[') + std::string(depth, ']'); }

// `doc` written as .gltf or .glb with its "extras" (a placeholder string) replaced by arrays nested
// `depth` deep. The placeholder has the nesting's length, so the GLB's chunk lengths stay right.
std::string write_with_deep_extras(GltfBuilder& b, const std::string& path, size_t depth, bool binary) {
  const std::string placeholder(2 * depth - 2, 'x');
  b.doc["extras"] = placeholder;
  binary ? b.write_glb(path) : b.write_gltf(path);
  std::ifstream in(path, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  bytes.replace(bytes.find("\"" + placeholder + "\""), 2 * depth, nested_arrays(depth));
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

TEST(SceneLoadLimits, JsonNestedDeeperThanTheLimitIsRefusedBeforeParsing) {
  const std::string simple = R"({"a":[[1],{"b":2}]})";
  EXPECT_EQ(json_nesting_depth(simple.data(), simple.size()), 3u);
  const std::string quoted = R"({"s":"[[[{{\"[[[["})";  // brackets in a string, an escaped quote
  EXPECT_EQ(json_nesting_depth(quoted.data(), quoted.size()), 1u);
  const std::string dir = temp_dir();
  // 20,000 deep (a 40 KB file): tinygltf's recursive conversion of "extras" overflowed the stack.
  GltfBuilder top;
  top.add_quad_scene();
  const std::string gltf = write_with_deep_extras(top, dir + "/top.gltf", 20000, false);
  EXPECT_EQ(error_of([&] { load_scene(gltf); }),
            gltf + ": JSON nested deeper than 256 levels (arrays and objects), which pxf does not read");
  const std::string glb = write_with_deep_extras(top, dir + "/top.glb", 20000, true);
  EXPECT_NE(error_of([&] { load_scene(glb); }).find("top.glb: JSON nested deeper than 256 levels"), std::string::npos);
  // In a node, as the fuzzer's harness reads it (from memory).
  GltfBuilder in_node;
  in_node.scene({in_node.node({{"mesh", in_node.mesh(in_node.quad_primitive())}, {"extras", "deep"}})});
  in_node.write_gltf(dir + "/node.gltf");
  std::ifstream in(dir + "/node.gltf");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  text.replace(text.find("\"deep\""), 6, nested_arrays(20000));
  const std::vector<unsigned char> bytes(text.begin(), text.end());
  EXPECT_NE(error_of([&] { load_scene_from_memory(bytes, "node.gltf", dir); }).find("nested deeper than 256"), std::string::npos);
  // At the limit it loads.
  EXPECT_NO_THROW(load_scene(write_with_deep_extras(top, dir + "/ok.glb", 255, true)));
}

TEST(SceneLoadLimits, TextureTransformAndAttributesOfAnyFiniteSizeStayFinite) {
  const std::string dir = temp_dir();
  GltfBuilder b;
  const int texture = b.texture(b.image(encode_png(2, 2, 3, 8, std::vector<uint32_t>(12, 200))));
  const json transform = {{"offset", {3e38, -3e38}}, {"scale", {3e38, 3e38}}, {"rotation", 0.3}};
  const int material = b.material({{"pbrMetallicRoughness",
                                    {{"baseColorTexture", {{"index", texture}, {"extensions", {{"KHR_texture_transform", transform}}}}}}}});
  json quad = b.quad_primitive(material);
  quad["attributes"]["TEXCOORD_0"] = b.floats({3e38f, -3e38f, 1, 1, 1, 0, 0, 0}, "VEC2");
  quad["attributes"]["COLOR_0"] = b.floats({3e38f, 2, 0.5f, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1}, "VEC4");
  b.scene({b.node({{"mesh", b.mesh(quad)}})});
  b.doc["extensionsUsed"] = {"KHR_texture_transform"};
  const Scene scene = load_scene(b.write_gltf(dir + "/transform.gltf"));
  EXPECT_TRUE(any_warning_contains(scene, "base color texture transform has an offset or scale beyond +-1.68e+07; clamped to it"))
      << warnings_of(scene);
  const TextureRef& ref = scene.materials[0].base_color_texture;
  ASSERT_TRUE(ref.valid());
  // What the raster pass computes: the transform of every UV, times the base color, texel and vertex color.
  for (const glm::vec2& uv : scene.meshes[0].uv0) {
    const glm::vec3 mapped = ref.transform * glm::vec3(uv, 1.0f);
    EXPECT_TRUE(std::isfinite(mapped.x) && std::isfinite(mapped.y)) << uv.x << ", " << uv.y;
  }
  for (const glm::vec4& c : scene.meshes[0].colors)
    EXPECT_TRUE(glm::all(glm::lessThanEqual(c, glm::vec4(1.0f))) && glm::all(glm::greaterThanEqual(c, glm::vec4(0.0f))));
  EXPECT_EQ(scene.meshes[0].colors[0], glm::vec4(1.0f, 1.0f, 0.5f, 1.0f));
}

// Nodes that instance `leaf` 10^levels times (each level references the next ten times).
int instancing_tree(GltfBuilder& b, const json& leaf, int levels) {
  int next = b.node(leaf);
  for (int level = 0; level < levels; ++level) next = b.node({{"children", std::vector<int>(10, next)}});
  return next;
}

TEST(SceneLoadLimits, InstancedLightsAndPrimitivesAreInTheEstimate) {
  const std::string dir = temp_dir();
  LoadLimits limits;
  limits.available_memory = 100ull << 20;
  // 10^6 instanced point lights, a 1 KB file: 305 MiB at 320 B a light. They were not counted.
  GltfBuilder lights;
  lights.doc["extensionsUsed"] = {"KHR_lights_punctual"};
  lights.doc["extensions"]["KHR_lights_punctual"]["lights"] = json::array({{{"type", "point"}, {"intensity", 1}}});
  lights.scene({lights.node({{"mesh", lights.mesh(lights.quad_primitive())}}),
                instancing_tree(lights, {{"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}}, 6)});
  const std::string lights_path = lights.write_gltf(dir + "/lights.gltf");
  std::string msg = error_of([&] { load_scene(lights_path, "", 1.0f, DefaultLight::None, limits); });
  EXPECT_NE(msg.find("loading needs an estimated 305 MiB (2 triangles, 1000000 lights, 0 MiB of textures)"), std::string::npos) << msg;
  // 10^4 instances of a quad: 8 KB each for its Mesh, BVH geometry and draw (a little more than they take),
  // where the estimate had only the vertices and triangles (10 MiB).
  GltfBuilder quads;
  quads.scene({instancing_tree(quads, {{"mesh", quads.mesh(quads.quad_primitive())}}, 4)});
  const std::string quads_path = quads.write_gltf(dir + "/quads.gltf");
  limits.available_memory = 50ull << 20;
  msg = error_of([&] { load_scene(quads_path, "", 1.0f, DefaultLight::None, limits); });
  EXPECT_NE(msg.find("loading needs an estimated 103 MiB (20000 triangles"), std::string::npos) << msg;
  limits.available_memory = 128ull << 20;
  EXPECT_EQ(load_scene(quads_path, "", 1.0f, DefaultLight::None, limits).estimated_load_bytes,
            10000u * (4 * 200 + 2 * (136 + 768) + 8192));
  LoadEstimate e;
  e.meshes = 3;
  e.lights = 5;
  e.environment_texels = 7;
  EXPECT_EQ(e.bytes(), 3u * 8192 + 5u * 320 + 7u * 40);
}

TEST(SceneLoadLimits, EnvironmentMapIsUnderTheTextureSizeCapAndInTheEstimate) {
  const std::string dir = temp_dir();
  GltfBuilder b;
  b.add_quad_scene();
  const std::string scene = b.write_gltf(dir + "/quad.gltf");
  const std::string env = dir + "/env.exr";
  write_exr(env, Image::rgb(64, 32, 1.0f));
  LoadLimits limits;
  limits.max_texture_size = 16;
  EXPECT_EQ(error_of([&] { load_scene(scene, env, 1.0f, DefaultLight::None, limits); }),
            env + ": environment map is 64x32, over the texture size limit of 16 (raise it with --max-texture-size)");
  limits.max_texture_size = 64;
  limits.available_memory = 64 * 32 * 40 - 1;  // the environment alone, before it is decoded
  EXPECT_NE(error_of([&] { load_scene(scene, env, 1.0f, DefaultLight::None, limits); })
                .find(env + ": loading needs an estimated 0.0781 MiB (0 triangles, 0 MiB of textures, an environment map of 2048 texels)"),
            std::string::npos);
  limits.available_memory = 64 * 32 * 40 + 4096;  // with the scene's quad
  EXPECT_NE(error_of([&] { load_scene(scene, env, 1.0f, DefaultLight::None, limits); }).find("quad.gltf: loading needs an estimated"),
            std::string::npos);
  limits.available_memory = 1ull << 30;
  const Scene loaded = load_scene(scene, env, 1.0f, DefaultLight::None, limits);
  ASSERT_TRUE(loaded.environment.has_value());
  EXPECT_EQ(loaded.estimated_load_bytes, 64u * 32 * 40 + 4 * 200 + 2 * (136 + 768) + 8192);
}

// A grid of 2 side^2 triangles in the XY plane, positions and uint32 indices only: the grid_SIDE
// input of scripts/memory_inputs.py.
std::string write_grid(const std::string& path, int side) {
  std::vector<float> positions;
  for (int j = 0; j <= side; ++j)
    for (int i = 0; i <= side; ++i)
      positions.insert(positions.end(), {static_cast<float>(i) / side, static_cast<float>(j) / side, 0.0f});
  std::vector<uint32_t> indices;
  for (int j = 0; j < side; ++j)
    for (int i = 0; i < side; ++i) {
      const uint32_t a = static_cast<uint32_t>(j * (side + 1) + i), row = static_cast<uint32_t>(side + 1);
      indices.insert(indices.end(), {a, a + 1, a + row + 1, a, a + row + 1, a + row});
    }
  GltfBuilder b;
  b.scene({b.node({{"mesh", b.mesh({{"attributes", {{"POSITION", b.floats(positions, "VEC3")}}}, {"indices", b.indices(indices)}})}})});
  return b.write_gltf(path);
}

// The promise of docs/robustness.md ("Memory"): the peak resident memory of a render, above the
// base that one triangle takes, is at most the estimate plus 20 %, and the estimate is at most
// twice that peak. The rows are that section's measured geometry inputs (scripts/measure_memory.sh:
// pxf render --spp 1 --size 16x16 on llvmpipe; the highest of the repeated runs): instanced
// vertices, triangles and primitives, and the peak above the base in MiB.
TEST(SceneLoadLimits, TheEstimateHoldsTheMeasuredPeaks) {
  struct Row {
    const char* input;
    uint64_t vertices, triangles, meshes;
    double peak_mib;
  };
  auto grid = [](const char* input, uint64_t side, double peak_mib) {
    return Row{input, (side + 1) * (side + 1), 2 * side * side, 1, peak_mib};
  };
  const Row rows[] = {
      grid("grid_50", 50, 3.9),
      grid("grid_100", 100, 17.6),
      grid("grid_150", 150, 41.3),
      grid("grid_200", 200, 73.5),
      grid("grid_230", 230, 87.7),
      grid("draco_quantized_300", 300, 99.4),
      grid("draco_quantized_600", 600, 191.2),
      grid("draco_quantized_1000", 1000, 479.7),
      grid("draco_quantized_1150", 1150, 663.7),
      {"meshes_1000_of_5", 1000 * 36, 1000 * 50, 1000, 52.0},
      {"meshes_100_of_20", 100 * 441, 100 * 800, 100, 74.4},
      {"nodes_3_of_100", 3 * 10201, 3 * 20000, 3, 55.2},
      {"nodes_10_of_100", 10 * 10201, 10 * 20000, 10, 102.9},
      {"nodes_40_of_100", 40 * 10201, 40 * 20000, 40, 289.2},
      {"nodes_100_of_100", 100 * 10201, 100 * 20000, 100, 538.2},
      {"gpu_200_of_50", 200 * 2601, 200 * 5000, 200, 298.5},
      {"gpu_1000_of_20", 1000 * 441, 1000 * 800, 1000, 349.2},
  };
  for (const Row& row : rows) {
    LoadEstimate e;
    e.vertices = row.vertices;
    e.triangles = row.triangles;
    e.meshes = row.meshes;
    const double estimate_mib = static_cast<double>(e.bytes()) / (1024.0 * 1024.0);
    EXPECT_LE(row.peak_mib, 1.2 * estimate_mib) << row.input << ": estimated " << estimate_mib << " MiB";
    EXPECT_LE(estimate_mib, 2.0 * row.peak_mib) << row.input << ": estimated " << estimate_mib << " MiB";
  }
  // The loader counts a grid as the rows do.
  const Scene loaded = load_scene(write_grid(temp_dir() + "/grid_200.gltf", 200));
  LoadEstimate e;
  e.vertices = 201 * 201;
  e.triangles = 2 * 200 * 200;
  e.meshes = 1;
  EXPECT_EQ(loaded.estimated_load_bytes, e.bytes());
  EXPECT_EQ(e.bytes(), 201u * 201 * 200 + 80000u * (136 + 768) + 8192);
  // Past 160 MiB of bins (218,453 triangles) the raster pass's share stops growing.
  e.triangles = 10'000'000;
  EXPECT_EQ(e.bytes(), 201u * 201 * 200 + 10'000'000u * 136 + (160u << 20) + 8192);
}

}  // namespace
}  // namespace pxf
