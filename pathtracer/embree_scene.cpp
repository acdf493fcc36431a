#include "pathtracer/embree_scene.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>

#include "image/image.h"
#include "pathtracer/bsdf.h"
#include "pathtracer/ray_recorder.h"
#include "scene/texture.h"

namespace pxf {
namespace {

// Inlined: at every hit (position, normal, uvs), where a call cost about a third of its work.
template <typename T>
[[gnu::always_inline]] inline T interpolate(const std::vector<T>& attribute, const glm::uvec3& tri, float u, float v) {
  return attribute[tri.x] * (1.0f - u - v) + attribute[tri.y] * u + attribute[tri.z] * v;
}

glm::vec2 interpolate_uv(const std::vector<glm::vec2>& uv, const glm::uvec3& tri, float u, float v) {
  return uv.empty() ? glm::vec2(0.0f) : interpolate(uv, tri, u, v);
}

// splitmix64's finalizer: every input bit flips about half of the output bits.
uint64_t mix_bits(uint64_t h) {
  h = (h ^ (h >> 30)) * 0xbf58476d1ce4e5b9ULL;
  h = (h ^ (h >> 27)) * 0x94d049bb133111ebULL;
  return h ^ (h >> 31);
}

// A uniform number in [0, 1) fixed by the ray (origin and direction) and the triangle it hits:
// Embree may report one hit more than once, and every report must be decided alike; different
// rays (other pixels, jitters, bounces, shadow rays) decide independently.
float hit_random(const RTCFilterFunctionNArguments* args, unsigned i, unsigned prim) {
  const unsigned n = args->N;
  const float parts[] = {RTCRayN_org_x(args->ray, n, i), RTCRayN_org_y(args->ray, n, i), RTCRayN_org_z(args->ray, n, i),
                         RTCRayN_dir_x(args->ray, n, i), RTCRayN_dir_y(args->ray, n, i), RTCRayN_dir_z(args->ray, n, i)};
  uint64_t h = mix_bits(static_cast<uint64_t>(prim) + 0x9e3779b97f4a7c15ULL * (RTCHitN_geomID(args->hit, n, i) + 1));
  for (float part : parts) {
    uint32_t bits;
    std::memcpy(&bits, &part, sizeof(bits));
    h = mix_bits(h ^ bits);
  }
  return static_cast<float>(h >> 40) * 0x1p-24f;
}

// Embree filter for MASK and BLEND materials, on camera, bounce and shadow rays alike: MASK
// rejects hits whose opacity is below the alpha cutoff; BLEND keeps a hit with probability equal
// to its opacity (stochastic transparency: in expectation the surface is blended over what is behind).
void alpha_filter(const RTCFilterFunctionNArguments* args) {
  const auto* data = static_cast<const EmbreeScene::MaskData*>(args->geometryUserPtr);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] == 0) continue;
    unsigned prim = RTCHitN_primID(args->hit, args->N, i);
    float u = RTCHitN_u(args->hit, args->N, i), v = RTCHitN_v(args->hit, args->N, i);
    const glm::uvec3& tri = data->mesh->triangles[prim];
    glm::vec2 uv0 = interpolate_uv(data->mesh->uv0, tri, u, v);
    glm::vec2 uv1 = interpolate_uv(data->mesh->uv1, tri, u, v);
    float vertex_alpha = data->mesh->colors.empty() ? 1.0f : interpolate(data->mesh->colors, tri, u, v).a;
    float opacity = eval_opacity(*data->scene, *data->material, uv0, uv1, vertex_alpha);
    const bool kept = data->material->alpha_mode == AlphaMode::Mask ? opacity >= data->material->alpha_cutoff
                                                                      : hit_random(args, i, prim) < opacity;
    if (!kept) args->valid[i] = 0;
  }
}

void embree_error(void*, RTCError code, const char* message) {
  // Only reported through the return values of the calls; build errors throw below.
  (void)code;
  (void)message;
}

}  // namespace

EmbreeScene::EmbreeScene(const Scene& scene) : scene_(scene) {
  device_ = rtcNewDevice(nullptr);
  if (!device_) throw Error("embree: cannot create a device (error " + std::to_string(rtcGetDeviceError(nullptr)) + ")");
  rtcSetDeviceErrorFunction(device_, embree_error, nullptr);
  rtc_scene_ = rtcNewScene(device_);
  rtcSetSceneBuildQuality(rtc_scene_, RTC_BUILD_QUALITY_HIGH);
  mask_data_.reserve(scene.meshes.size());  // filter functions keep pointers into it
  face_normals_.resize(scene.meshes.size());
  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    const Mesh& mesh = scene.meshes[m];
    auto& normals = face_normals_[m];
    normals.resize(mesh.triangles.size());
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
      const glm::uvec3& tri = mesh.triangles[t];
      glm::vec3 n = glm::cross(mesh.positions[tri.y] - mesh.positions[tri.x], mesh.positions[tri.z] - mesh.positions[tri.x]);
      float len = glm::length(n);
      normals[t] = len > 0.0f ? n / len : glm::vec3(0.0f, 0.0f, 1.0f);
    }
    RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                                 3 * sizeof(float), mesh.positions.size()));
    if (!mesh.positions.empty()) std::memcpy(vertices, mesh.positions.data(), mesh.positions.size() * sizeof(glm::vec3));
    auto* indices = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                   3 * sizeof(unsigned), mesh.triangles.size()));
    if (!mesh.triangles.empty()) std::memcpy(indices, mesh.triangles.data(), mesh.triangles.size() * sizeof(glm::uvec3));
    const Material& material = scene.materials[mesh.material];
    if (material.alpha_mode != AlphaMode::Opaque) {
      mask_data_.push_back({&scene_, &mesh, &material});
      rtcSetGeometryUserData(geom, &mask_data_.back());
      rtcSetGeometryIntersectFilterFunction(geom, alpha_filter);
      rtcSetGeometryOccludedFilterFunction(geom, alpha_filter);
    }
    rtcCommitGeometry(geom);
    unsigned id = rtcAttachGeometry(rtc_scene_, geom);  // ids are sequential: id == mesh index
    rtcReleaseGeometry(geom);
    if (id != m) throw Error("embree: unexpected geometry id");
  }
  rtcCommitScene(rtc_scene_);
  RTCError err = rtcGetDeviceError(device_);
  if (err != RTC_ERROR_NONE) throw Error("embree: building the BVH failed (error " + std::to_string(err) + ")");
}

EmbreeScene::~EmbreeScene() {
  if (rtc_scene_) rtcReleaseScene(rtc_scene_);
  if (device_) rtcReleaseDevice(device_);
}

namespace {

constexpr size_t kStreamChunk = kEmbreeStreamChunk;
// Every ray counts hits from its origin on (origins are offset off their surface instead); the
// ray recorder logs it as the ray's tmin.
constexpr float kRayTnear = 0.0f;
constexpr float kInfinity = std::numeric_limits<float>::infinity();

}  // namespace

Hit hit_of(const RTCRayHit& rh) {
  Hit hit;
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return hit;
  hit.mesh = rh.hit.geomID;
  hit.prim = rh.hit.primID;
  hit.u = rh.hit.u;
  hit.v = rh.hit.v;
  hit.t = rh.ray.tfar;
  return hit;
}

bool is_occluded(const RTCRay& r) { return r.tfar < 0.0f; }  // Embree sets tfar = -inf on occlusion

RTCIntersectContext intersect_context(RayCoherence coherence) {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = coherence == RayCoherence::Coherent ? RTC_INTERSECT_CONTEXT_FLAG_COHERENT
                                                      : RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
  return context;
}

RTCRay embree_ray(glm::vec3 origin, glm::vec3 direction, float tmax, float tnear) {
  RTCRay r;
  r.org_x = origin.x;
  r.org_y = origin.y;
  r.org_z = origin.z;
  r.dir_x = direction.x;
  r.dir_y = direction.y;
  r.dir_z = direction.z;
  r.tnear = tnear;
  r.tfar = tmax;
  r.time = 0.0f;
  r.mask = 0xffffffffu;
  r.id = 0;
  r.flags = 0;
  return r;
}

RTCRayHit embree_ray_hit(glm::vec3 origin, glm::vec3 direction, float tmax, float tnear) {
  RTCRayHit rh;
  rh.ray = embree_ray(origin, direction, tmax, tnear);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  return rh;
}

Hit EmbreeScene::intersect(const Ray& ray, float tmax) const {
  RTCIntersectContext context = intersect_context(RayCoherence::Incoherent);
  RTCRayHit rh = embree_ray_hit(ray.origin, ray.direction, tmax, kRayTnear);
  rtcIntersect1(rtc_scene_, &context, &rh);
  const Hit hit = hit_of(rh);
  if (__builtin_expect(recorder_ != nullptr, 0)) recorder_->closest(ray, kRayTnear, tmax, hit);
  return hit;
}

bool EmbreeScene::occluded(glm::vec3 origin, glm::vec3 direction, float tmax) const {
  RTCIntersectContext context = intersect_context(RayCoherence::Incoherent);
  RTCRay r = embree_ray(origin, direction, tmax, kRayTnear);
  rtcOccluded1(rtc_scene_, &context, &r);
  const bool blocked = is_occluded(r);
  if (__builtin_expect(recorder_ != nullptr, 0)) recorder_->shadow(origin, direction, kRayTnear, tmax, blocked);
  return blocked;
}

void EmbreeScene::intersect(const Ray* rays, size_t count, RayCoherence coherence, Hit* hits) const {
  RTCIntersectContext context = intersect_context(coherence);
  RTCRayHit chunk[kStreamChunk];
  for (size_t begin = 0; begin < count; begin += kStreamChunk) {
    const size_t n = std::min(kStreamChunk, count - begin);
    for (size_t i = 0; i < n; ++i)
      chunk[i] = embree_ray_hit(rays[begin + i].origin, rays[begin + i].direction, kInfinity, kRayTnear);
    rtcIntersect1M(rtc_scene_, &context, chunk, static_cast<unsigned>(n), sizeof(RTCRayHit));
    for (size_t i = 0; i < n; ++i) hits[begin + i] = hit_of(chunk[i]);
  }
  if (__builtin_expect(recorder_ != nullptr, 0))
    recorder_->closest_stream(rays, count, kStreamChunk, coherence, kRayTnear, kInfinity, hits);
}

void EmbreeScene::occluded(const ShadowRay* rays, size_t count, bool* occluded) const {
  RTCIntersectContext context = intersect_context(RayCoherence::Incoherent);
  RTCRay chunk[kStreamChunk];
  for (size_t begin = 0; begin < count; begin += kStreamChunk) {
    const size_t n = std::min(kStreamChunk, count - begin);
    for (size_t i = 0; i < n; ++i) {
      const ShadowRay& ray = rays[begin + i];
      chunk[i] = embree_ray(ray.origin, ray.direction, ray.tmax, kRayTnear);
    }
    rtcOccluded1M(rtc_scene_, &context, chunk, static_cast<unsigned>(n), sizeof(RTCRay));
    for (size_t i = 0; i < n; ++i) occluded[begin + i] = is_occluded(chunk[i]);
  }
  if (__builtin_expect(recorder_ != nullptr, 0)) recorder_->shadow_stream(rays, count, kStreamChunk, kRayTnear, occluded);
}

float EmbreeScene::triangle_area(unsigned mesh, unsigned prim) const {
  const Mesh& m = scene_.meshes[mesh];
  const glm::uvec3& tri = m.triangles[prim];
  return 0.5f * glm::length(glm::cross(m.positions[tri.y] - m.positions[tri.x], m.positions[tri.z] - m.positions[tri.x]));
}

// A tangent-space normal map (glTF: +Y green up) applied to the vertex normal; *normal is left as
// it is where the tangent frame or the mapped normal degenerates. Always level 0, whatever the
// footprint: a mip of a normal map is flatter, and flatter shading normals reflect more light (with
// them the atrium came out 1.7 % brighter at 256 spp; base colour and roughness levels alone, 0.1 %).
void EmbreeScene::map_normal(const TextureRef& map, float scale, glm::vec4 tangent, const SurfacePoint& sp,
                             glm::vec3* normal) const {
  glm::vec3 t = glm::vec3(tangent) - sp.vertex_normal * glm::dot(glm::vec3(tangent), sp.vertex_normal);
  const float tl = glm::length(t);
  if (!(tl > 1e-8f)) return;
  t /= tl;
  const glm::vec3 b = glm::cross(sp.vertex_normal, t) * (tangent.w < 0.0f ? -1.0f : 1.0f);
  glm::vec3 m = glm::vec3(eval_texture(scene_, map, sp.uv0, sp.uv1, glm::vec4(0.5f, 0.5f, 1.0f, 1.0f)));
  m = m * 2.0f - 1.0f;
  m.x *= scale;
  m.y *= scale;
  const glm::vec3 mapped = t * m.x + b * m.y + sp.vertex_normal * m.z;
  const float ml = glm::length(mapped);
  if (ml > 1e-8f && std::isfinite(ml)) *normal = mapped / ml;
}

namespace {

// A cone of width cone_width meeting the triangle at `cos_incidence` covers (cone_width^2 /
// cos_incidence) of its area; that area's square root in uv0 units (the triangle's uv0 area over
// its world area) is the footprint the texture look-ups filter over.
float uv_footprint(const Mesh& mesh, const glm::uvec3& tri, float cone_width, float cos_incidence) {
  const glm::vec2 du = mesh.uv0[tri.y] - mesh.uv0[tri.x], dv = mesh.uv0[tri.z] - mesh.uv0[tri.x];
  const float uv_area = std::abs(du.x * dv.y - du.y * dv.x);
  const float world_area = glm::length(glm::cross(mesh.positions[tri.y] - mesh.positions[tri.x],
                                                  mesh.positions[tri.z] - mesh.positions[tri.x]));
  if (!(world_area > 0.0f)) return 0.0f;
  const float footprint = cone_width * std::sqrt(uv_area / (world_area * std::max(cos_incidence, 1e-2f)));
  return std::isfinite(footprint) ? footprint : 0.0f;
}

}  // namespace

SurfacePoint EmbreeScene::surface_point(const Hit& hit, const Ray& ray, float cone_width) const {
  const Mesh& mesh = scene_.meshes[hit.mesh];
  const glm::uvec3& tri = mesh.triangles[hit.prim];
  SurfacePoint sp;
  sp.position = interpolate(mesh.positions, tri, hit.u, hit.v);
  sp.geometric_normal = face_normals_[hit.mesh][hit.prim];
  sp.front_face = glm::dot(ray.direction, sp.geometric_normal) < 0.0f;
  sp.material = &scene_.materials[mesh.material];
  glm::vec3 n = mesh.normals.empty() ? sp.geometric_normal : interpolate(mesh.normals, tri, hit.u, hit.v);
  float len = glm::length(n);
  sp.vertex_normal = len > 0.0f && std::isfinite(len) ? n / len : sp.geometric_normal;
  sp.shading_normal = sp.vertex_normal;
  sp.uv0 = interpolate_uv(mesh.uv0, tri, hit.u, hit.v);
  sp.uv1 = interpolate_uv(mesh.uv1, tri, hit.u, hit.v);
  if (cone_width > 0.0f && !mesh.uv0.empty())
    sp.texture_footprint = uv_footprint(mesh, tri, cone_width, std::abs(glm::dot(ray.direction, sp.geometric_normal)));
  if (!mesh.colors.empty()) sp.color = interpolate(mesh.colors, tri, hit.u, hit.v);
  const Material& mat = *sp.material;
  sp.clearcoat_normal = sp.vertex_normal;
  if (!mesh.tangents.empty()) {
    const glm::vec4 tangent = interpolate(mesh.tangents, tri, hit.u, hit.v);
    if (mat.normal_texture.valid()) map_normal(mat.normal_texture, mat.normal_scale, tangent, sp, &sp.shading_normal);
    if (mat.clearcoat_normal_texture.valid())
      map_normal(mat.clearcoat_normal_texture, mat.clearcoat_normal_scale, tangent, sp, &sp.clearcoat_normal);
  }
  return sp;
}

}  // namespace pxf
