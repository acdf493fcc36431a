// Programmatic geometry for tests and benchmarks: spheres, quads, boxes, a look-at camera and a
// small Cornell-like box scene. Meshes come out in world space like the loader's.
#pragma once
#include <glm/glm.hpp>
#include "scene/scene.h"

namespace pxf {

// UV sphere with smooth normals; `inward` flips winding and normals (a closed room around a camera).
Mesh make_sphere(glm::vec3 center, float radius, int material, int segments = 48, int rings = 24, bool inward = false);
// Parallelogram corner, corner + u, corner + u + v, corner + v; the normal is normalize(cross(u, v)).
Mesh make_quad(glm::vec3 corner, glm::vec3 u, glm::vec3 v, int material);
// Axis-aligned box with flat outward faces.
Mesh make_box(glm::vec3 min_corner, glm::vec3 max_corner, int material);

Camera look_at_camera(glm::vec3 eye, glm::vec3 target, glm::vec3 up, float yfov);

// A sky of the same radiance in every direction.
Environment uniform_environment(float radiance);

Material make_diffuse(glm::vec3 albedo);  // Lambertian (metallic 0, KHR specular 0)
Material make_mirror(glm::vec3 tint = glm::vec3(1.0f));
Material make_glass(float ior = 1.5f, glm::vec3 tint = glm::vec3(1.0f));
Material make_conductor(glm::vec3 f0, float roughness);
Material make_emitter(glm::vec3 radiance);  // black diffuse surface that emits from its front side

// A closed room ([-1,1]^3, white diffuse walls facing in) lit only through a window in its +x wall
// (y in [0, 0.6], z in [-0.4, 0.4]) by sky_with_sun(); the camera stands inside, near the -x wall,
// looking at the floor where the sun falls and at the walls it lights.
Scene make_room_with_window();
// An 64 x 32 equirect sky: radiance 0.5 above the horizon, 0.1 below, and a sun of radiance 2000
// in the texel toward normalize(1, 0.8, 0.1) (through make_room_with_window's window onto its floor).
Environment sky_with_sun();

// Cornell-like box ([-1,1]^3, open towards +z, ceiling light), optionally with a mirror and a glass
// sphere; camera at z = 3.4 looking down -z.
Scene make_cornell_box(bool with_specular_spheres);

// The Cornell box with its mirror and glass spheres (specular chains: single-ray queries) and a
// half-transparent BLEND veil across the view (Embree's alpha filter on every kind of ray, which
// decides a hit by the ray's own numbers).
Scene make_cornell_with_veil();

}  // namespace pxf
