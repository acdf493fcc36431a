#include "testing/shapes.h"

#include <algorithm>

#include "scene/texture.h"

#include <cmath>
#include <glm/gtc/matrix_transform.hpp>

namespace pxf {

Mesh make_sphere(glm::vec3 center, float radius, int material, int segments, int rings, bool inward) {
  Mesh mesh;
  mesh.name = "sphere";
  mesh.material = material;
  const float pi = 3.14159265358979f;
  for (int r = 0; r <= rings; ++r) {
    float theta = pi * static_cast<float>(r) / rings;
    for (int s = 0; s <= segments; ++s) {
      float phi = 2.0f * pi * static_cast<float>(s) / segments;
      glm::vec3 n(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
      mesh.positions.push_back(center + radius * n);
      mesh.normals.push_back(inward ? -n : n);
      mesh.uv0.push_back(glm::vec2(static_cast<float>(s) / segments, static_cast<float>(r) / rings));
    }
  }
  for (int r = 0; r < rings; ++r) {
    for (int s = 0; s < segments; ++s) {
      unsigned a = r * (segments + 1) + s, b = a + segments + 1;
      // Outward winding: (a, a+1, b) has normal along +n for this parameterization.
      glm::uvec3 t0(a, a + 1, b), t1(a + 1, b + 1, b);
      if (r != 0) mesh.triangles.push_back(inward ? glm::uvec3(t0.x, t0.z, t0.y) : t0);
      if (r != rings - 1) mesh.triangles.push_back(inward ? glm::uvec3(t1.x, t1.z, t1.y) : t1);
    }
  }
  return mesh;
}

Mesh make_quad(glm::vec3 corner, glm::vec3 u, glm::vec3 v, int material) {
  Mesh mesh;
  mesh.name = "quad";
  mesh.material = material;
  mesh.positions = {corner, corner + u, corner + u + v, corner + v};
  glm::vec3 n = glm::normalize(glm::cross(u, v));
  mesh.normals.assign(4, n);
  mesh.uv0 = {glm::vec2(0, 1), glm::vec2(1, 1), glm::vec2(1, 0), glm::vec2(0, 0)};
  mesh.triangles = {glm::uvec3(0, 1, 2), glm::uvec3(0, 2, 3)};
  return mesh;
}

Mesh make_box(glm::vec3 lo, glm::vec3 hi, int material) {
  Mesh box;
  box.name = "box";
  box.material = material;
  glm::vec3 d = hi - lo;
  const Mesh faces[6] = {
      make_quad(lo, glm::vec3(0, d.y, 0), glm::vec3(d.x, 0, 0), material),                   // -z
      make_quad(glm::vec3(lo.x, lo.y, hi.z), glm::vec3(d.x, 0, 0), glm::vec3(0, d.y, 0), material),  // +z
      make_quad(lo, glm::vec3(0, 0, d.z), glm::vec3(0, d.y, 0), material),                   // -x
      make_quad(glm::vec3(hi.x, lo.y, lo.z), glm::vec3(0, d.y, 0), glm::vec3(0, 0, d.z), material),  // +x
      make_quad(lo, glm::vec3(d.x, 0, 0), glm::vec3(0, 0, d.z), material),                   // -y
      make_quad(glm::vec3(lo.x, hi.y, lo.z), glm::vec3(0, 0, d.z), glm::vec3(d.x, 0, 0), material),  // +y
  };
  for (const Mesh& f : faces) {
    unsigned base = static_cast<unsigned>(box.positions.size());
    box.positions.insert(box.positions.end(), f.positions.begin(), f.positions.end());
    box.normals.insert(box.normals.end(), f.normals.begin(), f.normals.end());
    box.uv0.insert(box.uv0.end(), f.uv0.begin(), f.uv0.end());
    for (glm::uvec3 t : f.triangles) box.triangles.push_back(t + glm::uvec3(base));
  }
  return box;
}

Camera look_at_camera(glm::vec3 eye, glm::vec3 target, glm::vec3 up, float yfov) {
  Camera camera;
  camera.camera_to_world = glm::inverse(glm::lookAt(eye, target, up));
  camera.yfov = yfov;
  return camera;
}

Material make_diffuse(glm::vec3 albedo) {
  Material m;
  m.name = "diffuse";
  m.base_color = glm::vec4(albedo, 1.0f);
  m.metallic = 0.0f;
  m.roughness = 1.0f;
  m.specular = 0.0f;
  return m;
}

Material make_mirror(glm::vec3 tint) {
  Material m;
  m.name = "mirror";
  m.base_color = glm::vec4(tint, 1.0f);
  m.metallic = 1.0f;
  m.roughness = 0.0f;
  return m;
}

Material make_glass(float ior, glm::vec3 tint) {
  Material m;
  m.name = "glass";
  m.base_color = glm::vec4(tint, 1.0f);
  m.metallic = 0.0f;
  m.roughness = 0.0f;
  m.transmission = 1.0f;
  m.ior = ior;
  return m;
}

Material make_conductor(glm::vec3 f0, float roughness) {
  Material m;
  m.name = "conductor";
  m.base_color = glm::vec4(f0, 1.0f);
  m.metallic = 1.0f;
  m.roughness = roughness;
  return m;
}

Material make_emitter(glm::vec3 radiance) {
  Material m = make_diffuse(glm::vec3(0.0f));
  m.name = "emitter";
  m.emissive = radiance;
  return m;
}

Scene make_cornell_box(bool with_specular_spheres) {
  Scene scene;
  scene.source = "test:cornell";
  scene.materials = {make_diffuse(glm::vec3(0.73f)), make_diffuse(glm::vec3(0.65f, 0.05f, 0.05f)),
                     make_diffuse(glm::vec3(0.12f, 0.45f, 0.15f)), make_emitter(glm::vec3(12.0f, 10.0f, 7.0f)),
                     make_mirror(glm::vec3(0.95f)), make_glass(1.5f)};
  enum { kWhite, kRed, kGreen, kLight, kMirror, kGlass };
  scene.meshes.push_back(make_quad(glm::vec3(-1, -1, 1), glm::vec3(2, 0, 0), glm::vec3(0, 0, -2), kWhite));  // floor
  scene.meshes.push_back(make_quad(glm::vec3(-1, 1, -1), glm::vec3(2, 0, 0), glm::vec3(0, 0, 2), kWhite));   // ceiling
  scene.meshes.push_back(make_quad(glm::vec3(-1, -1, -1), glm::vec3(2, 0, 0), glm::vec3(0, 2, 0), kWhite));  // back
  scene.meshes.push_back(make_quad(glm::vec3(-1, -1, 1), glm::vec3(0, 0, -2), glm::vec3(0, 2, 0), kRed));    // left
  scene.meshes.push_back(make_quad(glm::vec3(1, -1, -1), glm::vec3(0, 0, 2), glm::vec3(0, 2, 0), kGreen));   // right
  scene.meshes.push_back(make_quad(glm::vec3(-0.3f, 0.999f, -0.3f), glm::vec3(0.6f, 0, 0), glm::vec3(0, 0, 0.6f), kLight));
  if (with_specular_spheres) {
    scene.meshes.push_back(make_sphere(glm::vec3(-0.45f, -0.6f, -0.3f), 0.4f, kMirror));
    scene.meshes.push_back(make_sphere(glm::vec3(0.45f, -0.6f, 0.3f), 0.4f, kGlass));
  } else {
    scene.meshes.push_back(make_box(glm::vec3(-0.7f, -1.0f, -0.6f), glm::vec3(-0.1f, 0.2f, 0.0f), kWhite));
    scene.meshes.push_back(make_box(glm::vec3(0.1f, -1.0f, -0.1f), glm::vec3(0.7f, -0.4f, 0.5f), kWhite));
  }
  scene.camera = look_at_camera(glm::vec3(0, 0, 3.4f), glm::vec3(0, 0, 0), glm::vec3(0, 1, 0), 0.69f);
  return scene;
}

Scene make_room_with_window() {
  Scene scene;
  scene.materials = {make_diffuse(glm::vec3(0.7f))};
  const auto wall = [&](glm::vec3 corner, glm::vec3 u, glm::vec3 v) { scene.meshes.push_back(make_quad(corner, u, v, 0)); };
  wall(glm::vec3(-1, -1, -1), glm::vec3(0, 0, 2), glm::vec3(2, 0, 0));  // floor, facing +y
  wall(glm::vec3(-1, 1, -1), glm::vec3(2, 0, 0), glm::vec3(0, 0, 2));   // ceiling, facing -y
  wall(glm::vec3(-1, -1, -1), glm::vec3(2, 0, 0), glm::vec3(0, 2, 0));  // back (-z), facing +z
  wall(glm::vec3(-1, -1, 1), glm::vec3(0, 2, 0), glm::vec3(2, 0, 0));   // front (+z), facing -z
  wall(glm::vec3(-1, -1, -1), glm::vec3(0, 2, 0), glm::vec3(0, 0, 2));  // -x, facing +x
  // The +x wall, facing -x, around the window y in [0, 0.6], z in [-0.4, 0.4].
  wall(glm::vec3(1, -1, -1), glm::vec3(0, 0, 2), glm::vec3(0, 1, 0));       // below
  wall(glm::vec3(1, 0.6f, -1), glm::vec3(0, 0, 2), glm::vec3(0, 0.4f, 0));  // above
  wall(glm::vec3(1, 0, -1), glm::vec3(0, 0, 0.6f), glm::vec3(0, 0.6f, 0));  // beside, -z
  wall(glm::vec3(1, 0, 0.4f), glm::vec3(0, 0, 0.6f), glm::vec3(0, 0.6f, 0));  // beside, +z
  scene.environment = sky_with_sun();
  scene.camera = look_at_camera(glm::vec3(-0.9f, 0.3f, 0.85f), glm::vec3(0.4f, -0.5f, -0.4f), glm::vec3(0, 1, 0), 1.2f);
  return scene;
}

Environment sky_with_sun() {
  Environment env;
  env.image.width = 64;
  env.image.height = 32;
  env.image.texels.resize(64 * 32);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 64; ++x) {
      const float r = y < 16 ? 0.5f : 0.1f;  // v = theta / pi: the upper half is the sky
      env.image.texels[static_cast<size_t>(y) * 64 + x] = glm::vec4(r, r, r, 1.0f);
    }
  const glm::vec2 uv = equirect_uv(glm::normalize(glm::vec3(1.0f, 0.8f, 0.1f)));
  const int sx = std::min(static_cast<int>(uv.x * 64), 63), sy = std::min(static_cast<int>(uv.y * 32), 31);
  env.image.texels[static_cast<size_t>(sy) * 64 + sx] = glm::vec4(2000.0f, 2000.0f, 2000.0f, 1.0f);
  return env;
}

Environment uniform_environment(float radiance) {
  Environment env;
  env.image.width = 8;
  env.image.height = 4;
  env.image.texels.assign(32, glm::vec4(radiance, radiance, radiance, 1.0f));
  return env;
}

Scene make_cornell_with_veil() {
  Scene scene = make_cornell_box(true);
  Material veil = make_diffuse(glm::vec3(0.6f, 0.3f, 0.2f));
  veil.base_color.a = 0.5f;
  veil.alpha_mode = AlphaMode::Blend;
  scene.materials.push_back(veil);
  scene.meshes.push_back(make_quad(glm::vec3(-0.7f, -0.6f, 0.4f), glm::vec3(0.9f, 0, 0), glm::vec3(0, 1.2f, 0),
                                   static_cast<int>(scene.materials.size() - 1)));
  return scene;
}

}  // namespace pxf
