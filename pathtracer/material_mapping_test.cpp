// Furnace-style checks of the glTF -> BSDF mapping (docs/materials.md): each test writes a tiny
// glTF (a UV sphere, JSON + base64 data-URI buffer, a perspective camera), loads it through
// pxf::load_scene with a uniform white environment EXR, renders it with ProgressiveRenderer and
// compares the image with the answer the mapping implies.
//
// A convex sphere under a uniform environment of radiance 1: every path leaves the sphere after one
// reflection, so the pixel value is the BSDF's directional albedo for that pixel's view direction.
// For opaque materials the test also integrates the BSDF built from the *loaded* material (same
// shading normals, independent Monte Carlo) and requires the render to match that prediction, so a
// loader mapping error and an integrator error are told apart.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "image/image.h"
#include "pathtracer/bsdf.h"
#include "pathtracer/ggx_albedo.h"
#include "pathtracer/integrator.h"
#include "pathtracer/pathtracer.h"
#include "scene/camera.h"
#include "scene/load.h"
#include "testing/gltf_builder.h"
#include "testing/shapes.h"

namespace pxf {
namespace {

namespace fs = std::filesystem;

template <typename T>
void append_bytes(std::vector<uint8_t>& bin, const T* data, size_t count) {
  const auto* p = reinterpret_cast<const uint8_t*>(data);
  bin.insert(bin.end(), p, p + count * sizeof(T));
}

fs::path test_dir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  fs::path dir = fs::path(::testing::TempDir()) / ("pxf_material_mapping_" + std::string(info->name()));
  fs::create_directories(dir);
  return dir;
}

// A uniform environment of radiance 1 (8 x 4 equirect EXR).
std::string white_environment() {
  fs::path path = test_dir() / "white.exr";
  write_exr(path.string(), Image::rgb(8, 4, 1.0f));
  return path.string();
}

// A unit sphere at the origin with material `material_json` (one glTF material object) and a camera
// at (0, 0, camera_z) looking down -Z. `inward` flips the winding (front faces point inward).
std::string write_sphere_gltf(const std::string& material_json, float camera_z, float yfov, bool inward = false,
                              const std::string& extensions_used = "") {
  Mesh sphere = make_sphere(glm::vec3(0.0f), 1.0f, 0, 64, 32, inward);
  std::vector<uint8_t> bin;
  append_bytes(bin, sphere.positions.data(), sphere.positions.size());
  size_t normals_offset = bin.size();
  append_bytes(bin, sphere.normals.data(), sphere.normals.size());
  size_t indices_offset = bin.size();
  append_bytes(bin, sphere.triangles.data(), sphere.triangles.size());
  size_t n = sphere.positions.size();
  std::ostringstream j;
  j << R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0,1]}],)"
    << R"("nodes":[{"mesh":0},{"camera":0,"translation":[0,0,)" << camera_z << "]}],"
    << R"("cameras":[{"type":"perspective","perspective":{"yfov":)" << yfov
    << R"(,"aspectRatio":1,"znear":0.01,"zfar":100}}],)"
    << R"("meshes":[{"primitives":[{"attributes":{"POSITION":0,"NORMAL":1},"indices":2,"material":0}]}],)"
    << R"("materials":[)" << material_json << "],"
    << R"("accessors":[{"bufferView":0,"componentType":5126,"count":)" << n
    << R"(,"type":"VEC3","min":[-1,-1,-1],"max":[1,1,1]},)"
    << R"({"bufferView":1,"componentType":5126,"count":)" << n << R"(,"type":"VEC3"},)"
    << R"({"bufferView":2,"componentType":5125,"count":)" << sphere.triangles.size() * 3 << R"(,"type":"SCALAR"}],)"
    << R"("bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":)" << normals_offset << "},"
    << R"({"buffer":0,"byteOffset":)" << normals_offset << R"(,"byteLength":)" << indices_offset - normals_offset << "},"
    << R"({"buffer":0,"byteOffset":)" << indices_offset << R"(,"byteLength":)" << bin.size() - indices_offset << "}],"
    << R"("buffers":[{"byteLength":)" << bin.size() << R"(,"uri":"data:application/octet-stream;base64,)"
    << test::base64(bin) << "\"}]";
  if (!extensions_used.empty()) j << R"(,"extensionsUsed":[)" << extensions_used << "]";
  j << "}";
  fs::path path = test_dir() / "sphere.gltf";
  std::ofstream(path) << j.str();
  return path.string();
}

// At distance 3 with yfov 0.46 rad every pixel (corners included) sees the sphere: the image holds
// view angles from normal incidence at the center to ~75 degrees at the corners.
constexpr float kCameraZ = 3.0f;
constexpr float kFillingYfov = 0.46f;
constexpr int kSize = 24;

Scene load_furnace(const std::string& material_json, const std::string& extensions_used = "") {
  Scene scene = load_scene(write_sphere_gltf(material_json, kCameraZ, kFillingYfov, false, extensions_used),
                           white_environment());
  EXPECT_TRUE(scene.warnings.empty()) << scene.warnings.front();
  return scene;
}

TraceParams furnace_params(int max_vertices = 64) {
  TraceParams params;
  params.max_vertices = max_vertices;
  params.rr_start_vertex = 3;
  params.threads = 2;
  params.seed = 7;
  return params;
}

struct RenderResult {
  double mean = 0;                  // mean luminance over all pixels
  std::vector<double> pixels;       // luminance per pixel
};

RenderResult render(const Scene& scene, const TraceParams& params, int frames) {
  ProgressiveRenderer renderer(scene, params, kSize, kSize);
  for (int i = 0; i < frames; ++i) renderer.add_frame();
  const Accumulation& acc = renderer.accumulation();
  RenderResult r;
  for (size_t i = 0; i < acc.samples.size(); ++i) r.pixels.push_back(luminance(acc.lv_mean[i] + acc.hv_mean[i]));
  for (double v : r.pixels) r.mean += v;
  r.mean /= static_cast<double>(r.pixels.size());
  return r;
}

// The mapping's prediction for an opaque convex object in the white furnace: per pixel (center ray),
// the directional albedo of the Bsdf built from the loaded material, by sampling it (a simple LCG,
// independent of the renderer's streams). Returns the mean over pixels; -1 if a pixel misses.
double predicted_albedo(const Scene& scene, int samples_per_pixel, double* min_pixel = nullptr) {
  PathTracer tracer(scene);
  uint64_t state = 12345;
  auto uniform = [&state] {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<float>(state >> 40) * 0x1p-24f;
  };
  double total = 0, lowest = 1e30;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      Ray ray = camera_ray(scene.camera, kSize, kSize, x + 0.5f, y + 0.5f);
      Hit hit = tracer.geometry().intersect(ray);
      if (!hit.valid()) return -1.0;
      SurfacePoint sp = tracer.geometry().surface_point(hit, ray);
      Bsdf bsdf(eval_material(scene, *sp.material, sp.uv0, sp.uv1, sp.color), sp.shading_normal, sp.geometric_normal,
                -ray.direction, sp.front_face);
      double sum = 0;
      for (int s = 0; s < samples_per_pixel; ++s) {
        BsdfSample bs;
        float u_lobe = uniform();
        glm::vec2 u(uniform(), uniform());
        if (bsdf.sample(u_lobe, u, &bs)) sum += luminance(bs.weight);
      }
      double albedo = sum / samples_per_pixel;
      lowest = std::min(lowest, albedo);
      total += albedo;
    }
  if (min_pixel) *min_pixel = lowest;
  return total / (kSize * kSize);
}

// An independent prediction for GGX-based opaque materials: the directional albedo by quadrature
// over the hemisphere (cos-theta x phi grid), with the formulas written out here rather than taken
// from bsdf.cpp: height-correlated Smith G2, Schlick F on wo.h, Turquin's compensation 1 + f0 (1/E - 1)
// with E the same quadrature's albedo at F = 1, plus `lambert` x (1 - the compensated specular albedo).
double quadrature_albedo(double mu, double alpha, double f0, double f90, double lambert) {
  const double pi = 3.14159265358979323846;
  auto lambda = [alpha](double z) {
    double tan2 = std::max(0.0, 1.0 - z * z) / (z * z);
    return 0.5 * (-1.0 + std::sqrt(1.0 + alpha * alpha * tan2));
  };
  auto schlick = [f0, f90](double c) { return f0 + (f90 - f0) * std::pow(std::max(0.0, 1.0 - c), 5.0); };
  glm::dvec3 wo(std::sqrt(std::max(0.0, 1.0 - mu * mu)), 0.0, mu);
  const int n_theta = 192, n_phi = 96;  // phi over [0, pi], doubled by symmetry
  double with_fresnel = 0, white = 0;
  for (int i = 0; i < n_theta; ++i) {
    double ct = (i + 0.5) / n_theta, st = std::sqrt(1.0 - ct * ct);
    for (int j = 0; j < n_phi; ++j) {
      double phi = pi * (j + 0.5) / n_phi;
      glm::dvec3 wi(st * std::cos(phi), st * std::sin(phi), ct);
      glm::dvec3 h = glm::normalize(wo + wi);
      double a2 = alpha * alpha, t = h.z * h.z * (a2 - 1.0) + 1.0;
      double d = a2 / (pi * t * t);
      double g2 = 1.0 / (1.0 + lambda(mu) + lambda(ct));
      white += d * g2 / (4.0 * mu);
      with_fresnel += schlick(glm::dot(wo, h)) * d * g2 / (4.0 * mu);
    }
  }
  const double cell = (1.0 / n_theta) * (2.0 * pi / n_phi);
  const double specular = with_fresnel * cell * (1.0 + f0 * (1.0 / (white * cell) - 1.0));
  return specular + lambert * (1.0 - specular);
}

// The same prediction averaged over the image: per pixel center, the view cosine on the ideal unit
// sphere (the mesh's smooth normals deviate from it by far less than the tolerances used).
double quadrature_image_mean(const Scene& scene, double alpha, double f0, double f90, double lambert) {
  double total = 0;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      Ray ray = camera_ray(scene.camera, kSize, kSize, x + 0.5f, y + 0.5f);
      glm::dvec3 o(ray.origin), d = glm::normalize(glm::dvec3(ray.direction));
      double b = glm::dot(o, d), c = glm::dot(o, o) - 1.0, disc = b * b - c;
      if (disc <= 0.0) return -1.0;
      glm::dvec3 n = o + d * (-b - std::sqrt(disc));
      total += quadrature_albedo(std::max(1e-3, -glm::dot(d, n)), alpha, f0, f90, lambert);
    }
  return total / (kSize * kSize);
}

// The metallic-roughness core with optional extensions, as one glTF material object.
std::string material(float base, float metallic, float roughness, const std::string& extensions = "") {
  std::ostringstream m;
  m << R"({"pbrMetallicRoughness":{"baseColorFactor":[)" << base << "," << base << "," << base
    << R"(,1],"metallicFactor":)" << metallic << R"(,"roughnessFactor":)" << roughness << "}";
  if (!extensions.empty()) m << R"(,"extensions":{)" << extensions << "}";
  m << "}";
  return m.str();
}

const char* kNoSpecular = R"("KHR_materials_specular":{"specularFactor":0})";

// ----------------------------------------------------------------------------------------------

TEST(MaterialMapping, WhiteDiffuseWithoutSpecularLayerConservesEnergy) {
  // base color 1, metallic 0, roughness 1, KHR_materials_specular factor 0: pure Lambert, albedo 1.
  Scene scene = load_furnace(material(1.0f, 0.0f, 1.0f, kNoSpecular), "\"KHR_materials_specular\"");
  RenderResult r = render(scene, furnace_params(), 256);
  std::printf("white Lambert (specular 0): mean %.5f\n", r.mean);
  EXPECT_NEAR(r.mean, 1.0, 0.01);
  for (double v : r.pixels) ASSERT_NEAR(v, 1.0, 0.08);
}

TEST(MaterialMapping, WhiteDielectricOverWhiteLambertConservesEnergy) {
  // glTF's default dielectric at roughness 1: Lambert x (1 - E_specular(cos_o)) + the compensated
  // GGX specular (F0 0.04, F90 1, alpha 1), E_specular the specular layer's own albedo: all the
  // light is reflected. Required: render = independent quadrature of that model (0.5%), = the
  // loaded Bsdf's own albedo (0.5%), and within 1% of 1.
  Scene scene = load_furnace(material(1.0f, 0.0f, 1.0f));
  double min_pixel = 0;
  double predicted = predicted_albedo(scene, 4000, &min_pixel);
  double quadrature = quadrature_image_mean(scene, 1.0, 0.04, 1.0, 1.0);
  RenderResult r = render(scene, furnace_params(), 256);
  std::printf("white dielectric (specular 1): mean %.5f Bsdf %.5f quadrature %.5f (lowest pixel %.4f)\n", r.mean,
              predicted, quadrature, min_pixel);
  EXPECT_NEAR(r.mean, quadrature, 0.005);
  EXPECT_NEAR(r.mean, predicted, 0.005);
  EXPECT_NEAR(r.mean, 1.0, 0.01);
}

TEST(MaterialMapping, RoughWhiteMetalConservesEnergy) {
  // metallic 1, base color 1: Schlick F = 1 everywhere, and the single-scattering GGX lobe's loss
  // between microfacets (8.4% at normal incidence for roughness 0.5, 67% for roughness 1) is given
  // back by the compensation. Required at roughness 0.5, 0.7 and 1 (alpha 0.25, 0.49, 1): the
  // render within 1% of 1, and of the loaded Bsdf's albedo (0.5%).
  for (float roughness : {0.5f, 0.7f, 1.0f}) {
    Scene scene = load_furnace(material(1.0f, 1.0f, roughness));
    double predicted = predicted_albedo(scene, 1000);
    RenderResult r = render(scene, furnace_params(), 64);
    std::printf("rough metal %.1f: mean %.5f Bsdf %.5f (uncompensated at normal incidence %.5f)\n", roughness, r.mean,
                predicted, ggx_albedo(1.0f, roughness * roughness).total);
    EXPECT_NEAR(r.mean, predicted, 0.005) << roughness;
    EXPECT_NEAR(r.mean, 1.0, 0.01) << roughness;
  }
}

TEST(MaterialMapping, ClearcoatOverWhiteConservesEnergy) {
  // KHR_materials_clearcoat 1 (F0 0.04, compensated GGX) over the white dielectric at roughness 1:
  // the coat reflects E_coat(cos_o) and the base, which keeps all it gets, the rest. Required: the
  // render within 1% of 1 and of the loaded Bsdf's albedo (0.5%), with a rough and a smooth coat.
  for (float coat_roughness : {0.3f, 0.0f}) {
    std::ostringstream ext;
    ext << R"("KHR_materials_clearcoat":{"clearcoatFactor":1,"clearcoatRoughnessFactor":)" << coat_roughness << "}";
    Scene scene = load_furnace(material(1.0f, 0.0f, 1.0f, ext.str()), R"("KHR_materials_clearcoat")");
    EXPECT_FLOAT_EQ(scene.materials[0].clearcoat, 1.0f);
    double predicted = predicted_albedo(scene, 1000);
    RenderResult r = render(scene, furnace_params(), 64);
    std::printf("clearcoat %.1f over white: mean %.5f Bsdf %.5f\n", coat_roughness, r.mean, predicted);
    EXPECT_NEAR(r.mean, predicted, 0.005) << coat_roughness;
    EXPECT_NEAR(r.mean, 1.0, 0.01) << coat_roughness;
  }
}

TEST(MaterialMapping, SheenOverWhiteConservesEnergy) {
  // KHR_materials_sheen, white sheen color, over the white dielectric at roughness 1: the sheen
  // reflects E_sheen(cos_o), the base (which keeps all it gets) is scaled by 1 - E_sheen(cos_o), the
  // extension's energy bound for a white sheen being 1. Required: within 1% of 1 and of the
  // loaded Bsdf's albedo (0.5%).
  const std::string ext = R"("KHR_materials_sheen":{"sheenColorFactor":[1,1,1],"sheenRoughnessFactor":0.5})";
  Scene scene = load_furnace(material(1.0f, 0.0f, 1.0f, ext), R"("KHR_materials_sheen")");
  EXPECT_FLOAT_EQ(scene.materials[0].sheen_roughness, 0.5f);
  double predicted = predicted_albedo(scene, 1000);
  RenderResult r = render(scene, furnace_params(), 64);
  std::printf("sheen over white: mean %.5f Bsdf %.5f\n", r.mean, predicted);
  EXPECT_NEAR(r.mean, predicted, 0.005);
  EXPECT_NEAR(r.mean, 1.0, 0.01);
}

// A black, specular-free sphere with base alpha `alpha` in `mode` ("BLEND" or "MASK", cutoff 0.5).
std::string cutout_material(float alpha, const char* mode) {
  std::ostringstream m;
  m << R"({"pbrMetallicRoughness":{"baseColorFactor":[0,0,0,)" << alpha
    << R"(],"metallicFactor":0,"roughnessFactor":1},"alphaMode":")" << mode
    << R"(","extensions":{"KHR_materials_specular":{"specularFactor":0}}})";
  return m.str();
}

TEST(MaterialMapping, BlendIsStochasticTransparencyConsistentWithMask) {
  // Every camera ray crosses the sphere twice (front face, back face): with BLEND each crossing
  // passes with probability 1 - alpha, so the white environment shows through (1 - alpha)^2 of
  // the time and the black surface the rest. MASK is the same surface thresholded at the cutoff.
  struct Case {
    float alpha;
    const char* mode;
    double expected;
  };
  for (const Case& c : {Case{0.3f, "BLEND", 0.49}, Case{1.0f, "BLEND", 0.0}, Case{0.0f, "BLEND", 1.0},
                        Case{0.3f, "MASK", 1.0}, Case{0.8f, "MASK", 0.0}}) {
    Scene scene = load_furnace(cutout_material(c.alpha, c.mode), R"("KHR_materials_specular")");
    RenderResult r = render(scene, furnace_params(), 64);
    std::printf("%s alpha %.1f: mean %.5f (expected %.2f)\n", c.mode, c.alpha, r.mean, c.expected);
    EXPECT_NEAR(r.mean, c.expected, 0.015) << c.mode << " " << c.alpha;  // 5 sigma of 36864 Bernoulli samples
  }
}

TEST(MaterialMapping, BlendShadowRaysAgreeWithCameraRays) {
  // Shadow rays see a BLEND surface exactly when a ray along the same line hits it (both filters
  // draw the same number for the same ray and triangle), and pass it with probability 1 - alpha.
  Scene scene = load_furnace(cutout_material(0.25f, "BLEND"), R"("KHR_materials_specular")");
  PathTracer tracer(scene);
  int passed = 0, disagreements = 0;
  const int rays = 4000;
  for (int i = 0; i < rays; ++i) {
    const glm::vec3 origin(-0.4f + 0.8f * ((i % 63) + 0.5f) / 63.0f, -0.4f + 0.8f * ((i / 63) + 0.5f) / 64.0f, 3.0f);
    const Ray ray{origin, glm::vec3(0.0f, 0.0f, -1.0f)};
    const bool hit = tracer.geometry().intersect(ray).valid();
    const bool occluded = tracer.geometry().occluded(origin, ray.direction, 10.0f);
    disagreements += hit != occluded;
    passed += !occluded;
  }
  const double p = 0.75 * 0.75, sigma = std::sqrt(p * (1.0 - p) / rays);
  std::printf("BLEND 0.25: %.4f of the shadow rays pass (expected %.4f)\n", static_cast<double>(passed) / rays, p);
  EXPECT_EQ(disagreements, 0);
  EXPECT_NEAR(static_cast<double>(passed) / rays, p, 4.0 * sigma);
}

TEST(MaterialMapping, RoughnessIsSquaredIntoGgxAlpha) {
  // Perceptual roughness r maps to alpha = r^2: a metal at roughness 0.5 must equal the same
  // Bsdf with roughness 0.5 (alpha 0.25), and differ from a Bsdf with alpha 0.5 (roughness 0.707).
  Scene scene = load_furnace(material(1.0f, 1.0f, 0.5f));
  ASSERT_EQ(scene.materials.size(), 2u);  // ours + the loader's default
  EXPECT_FLOAT_EQ(scene.materials[0].roughness, 0.5f);
  EXPECT_FLOAT_EQ(scene.materials[0].metallic, 1.0f);
  // Grazing-ish view: the GGX lobe's directional albedo depends on alpha.
  glm::vec3 n(0, 0, 1), wo = glm::normalize(glm::vec3(0.9f, 0.0f, 0.3f));
  BsdfParams p = eval_material(scene, scene.materials[0], glm::vec2(0), glm::vec2(0), glm::vec4(1));
  Bsdf bsdf(p, n, n, wo, true);
  glm::vec3 wi = glm::normalize(glm::vec3(-0.9f, 0.0f, 0.3f));  // mirror direction
  glm::vec3 h = glm::normalize(wo + wi);
  float g = 1.0f / (1.0f + ggx_lambda(wo, 0.25f) + ggx_lambda(wi, 0.25f));
  // F = 1 for a white metal, and the compensation 1 / E(cos_o).
  float expected = ggx_d(h, 0.25f) * g / (4.0f * wo.z) / ggx_albedo(wo.z, 0.25f).total;
  EXPECT_NEAR(bsdf.eval(wi).x, expected, 1e-3f * expected);
  float other = ggx_d(h, 0.5f) / (1.0f + ggx_lambda(wo, 0.5f) + ggx_lambda(wi, 0.5f)) / (4.0f * wo.z) /
                ggx_albedo(wo.z, 0.5f).total;
  EXPECT_GT(std::abs(bsdf.eval(wi).x - other), 0.1f * expected);
}

TEST(MaterialMapping, PerfectMirrorReflectsSchlickOfItsBaseColor) {
  // metallic 1, roughness 0: a delta mirror with F = Schlick(F0 = base color 0.5, F90 = 1): 0.5 at
  // normal incidence, rising toward grazing. Deterministic per ray: compare each pixel region.
  Scene scene = load_furnace(material(0.5f, 1.0f, 0.0f));
  EXPECT_TRUE(material_is_perfect_mirror(scene.materials[0]));
  EXPECT_TRUE(material_is_perfect_specular(scene.materials[0]));
  double predicted = predicted_albedo(scene, 1);
  RenderResult r = render(scene, furnace_params(), 64);
  double center = 0;
  for (int y = kSize / 2 - 2; y < kSize / 2 + 2; ++y)
    for (int x = kSize / 2 - 2; x < kSize / 2 + 2; ++x) center += r.pixels[y * kSize + x] / 16.0;
  std::printf("mirror 0.5: center %.5f mean %.5f predicted %.5f\n", center, r.mean, predicted);
  EXPECT_NEAR(center, 0.5, 0.002);
  EXPECT_NEAR(r.mean, predicted, 0.003);
  EXPECT_GT(r.mean, 0.5);  // the Schlick rise toward grazing is part of the model
}

TEST(MaterialMapping, RoughnessJustAboveTheDeltaThresholdIsGlossy) {
  Scene delta = load_furnace(material(1.0f, 1.0f, 0.0009f));
  Scene glossy = load_furnace(material(1.0f, 1.0f, 0.0011f));
  EXPECT_TRUE(material_is_perfect_mirror(delta.materials[0]));
  EXPECT_FALSE(material_is_perfect_mirror(glossy.materials[0]));
  // A nearly-metal (metallic 0.99) is not a perfect mirror either: it has a diffuse part.
  Scene mixed = load_furnace(material(1.0f, 0.99f, 0.0f));
  EXPECT_FALSE(material_is_perfect_specular(mixed.materials[0]));
}

TEST(MaterialMapping, SmoothGlassIsEnergyConservingInTheWhiteFurnace) {
  const std::string ext = R"("KHR_materials_transmission":{"transmissionFactor":1},"KHR_materials_ior":{"ior":1.5})";
  Scene scene = load_furnace(material(1.0f, 0.0f, 0.0f, ext), R"("KHR_materials_transmission","KHR_materials_ior")");
  EXPECT_TRUE(material_is_perfect_specular(scene.materials[0]));
  EXPECT_FLOAT_EQ(scene.materials[0].ior, 1.5f);
  RenderResult r = render(scene, furnace_params(), 128);
  std::printf("smooth glass: mean %.5f\n", r.mean);
  EXPECT_NEAR(r.mean, 1.0, 0.01);
}

TEST(MaterialMapping, RoughGlassIsEnergyConservingInTheWhiteFurnace) {
  // transmission 1 above the delta roughness: Walter's rough dielectric, reflecting and refracting
  // at every crossing, and the compensation lobe that sends on what single scattering loses
  // between microfacets (without it: 0.976 at roughness 0.3, 0.734 at 0.6, where light crosses the
  // rough interface many times inside the sphere). White, it keeps all the light, as the smooth
  // glass does; its image is not the smooth glass's.
  const std::string ext = R"("KHR_materials_transmission":{"transmissionFactor":1},"KHR_materials_ior":{"ior":1.5})";
  const std::string used = R"("KHR_materials_transmission","KHR_materials_ior")";
  Scene smooth = load_furnace(material(1.0f, 0.0f, 0.0f, ext), used);
  const RenderResult reference = render(smooth, furnace_params(), 32);
  for (float roughness : {0.3f, 0.6f}) {
    Scene rough = load_furnace(material(1.0f, 0.0f, roughness, ext), used);
    EXPECT_FALSE(material_is_perfect_specular(rough.materials[0]));
    RenderResult r = render(rough, furnace_params(), 64);
    double largest_difference = 0;
    for (size_t i = 0; i < r.pixels.size(); ++i)
      largest_difference = std::max(largest_difference, std::abs(r.pixels[i] - reference.pixels[i]));
    std::printf("white rough glass %.1f: mean %.5f (smooth %.5f), largest pixel difference %.4f\n", roughness,
                r.mean, reference.mean, largest_difference);
    EXPECT_NEAR(r.mean, 1.0, 0.01) << roughness;
    EXPECT_GT(largest_difference, 0.02) << roughness;
  }
}

TEST(MaterialMapping, RoughGlassKeepsTheVolumeAbsorption) {
  // KHR_materials_volume on rough glass: Beer-Lambert on the segments inside, as for smooth glass.
  // Paths through a slightly rough sphere are about as long as through a smooth one, so absorption
  // darkens both by about the same factor.
  auto glass = [](float roughness, bool absorbing) {
    std::string ext = R"("KHR_materials_transmission":{"transmissionFactor":1})";
    if (absorbing) ext += R"(,"KHR_materials_volume":{"thicknessFactor":1,"attenuationDistance":1,"attenuationColor":[0.5,0.5,0.5]})";
    return material(1.0f, 0.0f, roughness, ext);
  };
  const std::string used = R"("KHR_materials_transmission","KHR_materials_volume")";
  double ratio[2];
  for (int rough = 0; rough < 2; ++rough) {
    const float roughness = rough ? 0.2f : 0.0f;
    const double clear = render(load_furnace(glass(roughness, false), used), furnace_params(), 32).mean;
    const double absorbing = render(load_furnace(glass(roughness, true), used), furnace_params(), 32).mean;
    ratio[rough] = absorbing / clear;
    std::printf("glass roughness %.1f: clear %.5f absorbing %.5f\n", roughness, clear, absorbing);
  }
  EXPECT_LT(ratio[1], 0.8);  // absorbed
  EXPECT_NEAR(ratio[1], ratio[0], 0.05);
}

TEST(MaterialMapping, SpecularFactorZeroMakesADielectricPurelyDiffuse) {
  // Half-grey dielectric: with KHR_materials_specular 0 the convex sphere reads exactly its albedo
  // 0.5 (one bounce, then the environment); the default specular layer reads differently.
  Scene plain = load_furnace(material(0.5f, 0.0f, 1.0f, kNoSpecular), "\"KHR_materials_specular\"");
  EXPECT_FLOAT_EQ(plain.materials[0].specular, 0.0f);
  RenderResult r = render(plain, furnace_params(), 256);
  std::printf("grey Lambert 0.5: mean %.5f\n", r.mean);
  EXPECT_NEAR(r.mean, 0.5, 0.005);

  Scene layered = load_furnace(material(0.5f, 0.0f, 1.0f));
  double predicted_layered = predicted_albedo(layered, 2000);
  double predicted_plain = predicted_albedo(plain, 2000);
  std::printf("grey predicted: specular 0 %.5f, specular 1 %.5f\n", predicted_plain, predicted_layered);
  EXPECT_NEAR(predicted_plain, 0.5, 0.003);
  EXPECT_GT(std::abs(predicted_layered - predicted_plain), 0.005);  // the specular layer is visible
}

TEST(MaterialMapping, SpecularColorAndIorSetTheDielectricF0) {
  // F0 = ((ior - 1) / (ior + 1))^2 x specularColorFactor, times specularFactor; F90 = specularFactor.
  // Probe the Bsdf from the loaded material at normal incidence through its Fresnel-weighted lobe:
  // with base color 0 only the specular layer remains, and a smooth one is a delta mirror.
  const std::string ext =
      R"("KHR_materials_ior":{"ior":2.0},"KHR_materials_specular":{"specularFactor":0.5,"specularColorFactor":[1,0.5,0.25]})";
  Scene scene = load_furnace(material(0.0f, 0.0f, 0.0f, ext), R"("KHR_materials_ior","KHR_materials_specular")");
  BsdfParams p = eval_material(scene, scene.materials[0], glm::vec2(0), glm::vec2(0), glm::vec4(1));
  glm::vec3 n(0, 0, 1);
  Bsdf bsdf(p, n, n, n, true);
  BsdfSample s;
  ASSERT_TRUE(bsdf.sample(0.5f, glm::vec2(0.5f), &s));
  ASSERT_TRUE(s.delta);
  float f0 = 1.0f / 9.0f;  // ((2 - 1) / (2 + 1))^2
  // weight = F / p_glossy with p_glossy = 1 (the only lobe); F(cos 1) = F0.
  EXPECT_NEAR(s.weight.x, 0.5f * f0 * 1.0f, 1e-5f);
  EXPECT_NEAR(s.weight.y, 0.5f * f0 * 0.5f, 1e-5f);
  EXPECT_NEAR(s.weight.z, 0.5f * f0 * 0.25f, 1e-5f);
}

// ----------------------------------------------------------------------------------------------
// Emission through glTF: emissiveFactor x KHR_materials_emissive_strength, front side only unless
// doubleSided, summed over bounces in a closed grey room (the furnace's geometric series).

double closed_room_mean(bool inward, bool double_sided, int max_vertices) {
  std::string m = R"({"pbrMetallicRoughness":{"baseColorFactor":[0.5,0.5,0.5,1],"metallicFactor":0,)"
                  R"("roughnessFactor":1},"emissiveFactor":[0.25,0.25,0.25],"doubleSided":)" +
                  std::string(double_sided ? "true" : "false") +
                  R"(,"extensions":{"KHR_materials_emissive_strength":{"emissiveStrength":4},)"
                  R"("KHR_materials_specular":{"specularFactor":0}}})";
  Scene scene = load_scene(write_sphere_gltf(m, 0.2f, 1.0f, inward,
                                             R"("KHR_materials_emissive_strength","KHR_materials_specular")"));
  EXPECT_TRUE(scene.warnings.empty());
  EXPECT_FLOAT_EQ(scene.materials[0].emissive.x, 1.0f);
  TraceParams params;
  params.max_vertices = max_vertices;
  params.rr_start_vertex = 100;  // exact truncation at the path-length limit
  params.threads = 2;
  return render(scene, params, 32).mean;
}

TEST(MaterialMapping, EmissionTimesStrengthSumsTheGeometricSeries) {
  for (int vertices : {2, 4, 6}) {
    double expected = 0;
    for (int k = 0; k < vertices - 1; ++k) expected += std::pow(0.5, k);  // Le = 0.25 x 4 = 1, albedo 0.5
    double mean = closed_room_mean(/*inward=*/true, /*double_sided=*/false, vertices);
    std::printf("closed room, %d vertices: %.5f (expected %.5f)\n", vertices, mean, expected);
    EXPECT_NEAR(mean, expected, 0.01 * expected) << vertices << " vertices";
  }
}

TEST(MaterialMapping, EmissionIsOneSidedUnlessDoubleSided) {
  // Inside an outward-facing sphere the camera sees only back faces: dark unless doubleSided.
  // (Not exactly 0: NEE between adjacent, nearly coplanar facets sees float-rounding cosines ~1e-8.)
  EXPECT_LT(closed_room_mean(/*inward=*/false, /*double_sided=*/false, 4), 1e-5);
  EXPECT_NEAR(closed_room_mean(/*inward=*/false, /*double_sided=*/true, 4), 1.75, 0.0175);
}

}  // namespace
}  // namespace pxf

// Figures for docs/scenes.md, not a pass/fail test (tests never assert wall time). Run with
//   pathtracer_tests --gtest_also_run_disabled_tests --gtest_filter=SceneFigures.*
#include <chrono>
namespace pxf {
namespace {
TEST(SceneFigures, DISABLED_BuiltinLoadTimes) {
  for (const BuiltinScene& builtin : builtin_scenes()) {
    double best = 1e30;
    Scene scene;
    for (int i = 0; i < 3; ++i) {
      auto t0 = std::chrono::steady_clock::now();
      scene = load_scene(builtin.name);
      best = std::min(best, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    }
    size_t emissive_meshes = 0, emissive_triangles = 0;
    for (const Mesh& mesh : scene.meshes)
      if (scene.materials[mesh.material].is_emissive()) {
        ++emissive_meshes;
        emissive_triangles += mesh.triangles.size();
      }
    std::printf("%s: load %.1f ms (best of 3), %zu triangles, %zu meshes, %zu textures, %zu punctual lights, "
                "%zu emissive meshes (%zu triangles), environment %s, %zu warnings\n",
                builtin.name.c_str(), best, scene.triangle_count(), scene.meshes.size(), scene.textures.size(),
                scene.lights.size(), emissive_meshes, emissive_triangles,
                scene.environment ? "yes" : "no", scene.warnings.size());
    for (const PunctualLight& l : scene.lights)
      std::printf("  light '%s' type %d intensity %.3g\n", l.name.c_str(), static_cast<int>(l.type), l.intensity);
    for (const std::string& w : scene.warnings) std::printf("  warning: %s\n", w.c_str());
    EXPECT_GT(scene.triangle_count(), 0u);
  }
}
}  // namespace
}  // namespace pxf
