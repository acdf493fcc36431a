#include "gl/range_pass.h"

#include <cstring>
#include "gl/gl.h"
#include "gl/pass_params.h"
#include "scene/camera.h"
#include "scene/material.h"

namespace pxf {
namespace {

// Interleaved vertex of the range pass; absent attributes get neutral values.
struct Vertex {
  glm::vec3 position, normal;
  glm::vec2 uv0, uv1;
  glm::vec4 color;
  glm::vec4 tangent;
};

GLint gl_wrap(Wrap w) {
  switch (w) {
    case Wrap::ClampToEdge: return GL_CLAMP_TO_EDGE;
    case Wrap::MirroredRepeat: return GL_MIRRORED_REPEAT;
    case Wrap::Repeat: break;
  }
  return GL_REPEAT;
}

bool same_camera(const Camera& a, const Camera& b) {
  return a.camera_to_world == b.camera_to_world && a.orthographic == b.orthographic && a.yfov == b.yfov &&
         a.ymag == b.ymag && a.znear == b.znear && a.zfar == b.zfar;
}

}  // namespace

struct RangePass::GpuMesh {
  Buffer vertices, indices;
  VertexArray vao;
  int index_count = 0;
  int material = 0;
  bool has_tangents = false;
};

RangePass::RangePass(int width, int height)
    : width_(width), height_(height), raster_(Program::from_embedded("range.vert", "range.frag")),
      points_(Program::from_embedded("specular_points.vert", "specular_points.frag")),
      accumulate_(Program::from_embedded("fullscreen.vert", "range_accumulate.frag")),
      background_(Program::from_embedded("fullscreen.vert", "range_background.frag")),
      frame_color_(width, height, TextureFormat::RGBA32F), frame_distance_(width, height, TextureFormat::R32F),
      frame_surface_(width, height, TextureFormat::RGBA32F), frame_depth_(width, height, TextureFormat::Depth32F),
      guide_{Texture2D(width, height, TextureFormat::RGBA32F), Texture2D(width, height, TextureFormat::RGBA32F)},
      surface_{Texture2D(width, height, TextureFormat::RGBA32F), Texture2D(width, height, TextureFormat::RGBA32F)},
      change_(width, height, TextureFormat::R32F), white_(1, 1, TextureFormat::RGBA32F) {
  frame_fbo_.attach(0, frame_color_);
  frame_fbo_.attach(1, frame_distance_);
  frame_fbo_.attach(2, frame_surface_);
  frame_fbo_.attach_depth(frame_depth_);
  frame_fbo_.check("range pass");
  for (int i = 0; i < 2; ++i) {
    accum_fbo_[i].attach(0, guide_[i]);
    accum_fbo_[i].attach(1, change_);
    accum_fbo_[i].attach(2, surface_[i]);
    accum_fbo_[i].check("range accumulation");
  }
  const float white[4] = {1, 1, 1, 1};
  white_.upload(white, 4);
  // An empty guide until the first frame: range color 0, background distance.
  const float clear[4] = {0, 0, 0, kBackgroundDepth};
  for (auto& g : guide_) glClearTexImage(g.id(), 0, GL_RGBA, GL_FLOAT, clear);
  const float no_surface[4] = {0, 0, 0, 0};  // normal unknown
  for (auto& s : surface_) glClearTexImage(s.id(), 0, GL_RGBA, GL_FLOAT, no_surface);
}

RangePass::~RangePass() = default;

void RangePass::set_scene(const Scene& scene) {
  meshes_.clear();
  textures_.clear();
  materials_ = scene.materials;
  has_specular_material_ = false;
  // The range color reads base color textures, the surface normal maps and metallic-roughness
  // textures; 8-bit ones stay 8-bit (GL decodes sRGB).
  std::vector<bool> used(scene.textures.size(), false);
  for (const Material& m : scene.materials)
    for (const TextureRef* ref : {&m.base_color_texture, &m.normal_texture, &m.metallic_roughness_texture})
      if (ref->valid() && ref->texture < static_cast<int>(used.size())) used[ref->texture] = true;
  for (size_t i = 0; i < scene.textures.size(); ++i) {
    const Texture& t = scene.textures[i];
    if (!used[i] || !t.valid()) {
      textures_.emplace_back();  // unused or invalid: the white texture is bound instead
      continue;
    }
    Texture2D tex(t.width, t.height,
                  t.is_8bit() ? (t.srgb ? TextureFormat::SRGB8_ALPHA8 : TextureFormat::RGBA8) : TextureFormat::RGBA32F);
    if (t.is_8bit()) tex.upload_rgba8(t.texels8->data());
    else tex.upload(&t.texels[0].x, 4);
    tex.set_filter(!t.nearest);  // bilinear without mipmaps, as the path tracer samples
    tex.set_wrap(gl_wrap(t.wrap_s), gl_wrap(t.wrap_t));
    textures_.push_back(std::move(tex));
  }
  upload_environment(scene);
  for (const Mesh& m : scene.meshes) {
    if (m.triangles.empty() || m.positions.empty()) continue;
    std::vector<Vertex> vertices(m.positions.size());
    for (size_t i = 0; i < vertices.size(); ++i) {
      Vertex& v = vertices[i];
      v.position = m.positions[i];
      v.normal = i < m.normals.size() ? m.normals[i] : glm::vec3(0, 0, 1);
      v.uv0 = i < m.uv0.size() ? m.uv0[i] : glm::vec2(0);
      v.uv1 = i < m.uv1.size() ? m.uv1[i] : glm::vec2(0);
      v.color = i < m.colors.size() ? m.colors[i] : glm::vec4(1);
      v.tangent = i < m.tangents.size() ? m.tangents[i] : glm::vec4(0, 0, 0, 1);
    }
    GpuMesh g;
    g.vertices = Buffer(vertices.size() * sizeof(Vertex), vertices.data());
    g.indices = Buffer(m.triangles.size() * sizeof(glm::uvec3), m.triangles.data());
    g.vao.attribute(0, g.vertices, 3, sizeof(Vertex), offsetof(Vertex, position));
    g.vao.attribute(1, g.vertices, 3, sizeof(Vertex), offsetof(Vertex, normal));
    g.vao.attribute(2, g.vertices, 2, sizeof(Vertex), offsetof(Vertex, uv0));
    g.vao.attribute(3, g.vertices, 2, sizeof(Vertex), offsetof(Vertex, uv1));
    g.vao.attribute(4, g.vertices, 4, sizeof(Vertex), offsetof(Vertex, color));
    g.vao.attribute(5, g.vertices, 4, sizeof(Vertex), offsetof(Vertex, tangent));
    g.has_tangents = !m.tangents.empty();
    g.vao.element_buffer(g.indices);
    g.index_count = static_cast<int>(m.triangles.size() * 3);
    g.material = (m.material >= 0 && m.material < static_cast<int>(materials_.size())) ? m.material : -1;
    if (g.material >= 0 && material_is_perfect_specular(materials_[g.material])) has_specular_material_ = true;
    meshes_.push_back(std::move(g));
  }
  check_gl_error("range pass scene upload");
  invalidate();
  if (!has_camera_) set_camera(scene.camera);
}

void RangePass::set_camera(const Camera& camera) {
  if (has_camera_ && same_camera(camera, camera_)) return;
  camera_ = camera;
  has_camera_ = true;
  invalidate();
}

glm::vec2 RangePass::jitter() const { return raster_jitter(frames_); }

void RangePass::upload_environment(const Scene& scene) {
  environment_ = Texture2D();
  environment_strength_ = 0.0f;
  if (!scene.environment || !(scene.environment->strength > 0.0f)) return;
  const Texture& image = scene.environment->image;
  if (image.width <= 0 || image.height <= 0 || image.texels.size() < static_cast<size_t>(image.width) * image.height)
    return;
  environment_ = Texture2D(image.width, image.height, TextureFormat::RGBA32F);
  environment_.upload(&image.texels[0].x, 4);
  environment_.set_filter(true);  // bilinear, as the path tracer samples it
  environment_.set_wrap(GL_REPEAT, GL_CLAMP_TO_EDGE);
  environment_strength_ = scene.environment->strength;
}

void RangePass::draw_environment(const glm::mat4& view_projection) {
  background_.set("inverse_view_projection", glm::inverse(view_projection));
  background_.set("size", glm::vec2(width_, height_));
  background_.set("strength", environment_strength_);
  background_.set("background_distance", kBackgroundDepth);
  background_.use();
  background_.bind(0, environment_);
  glDisable(GL_DEPTH_TEST);
  quad_.draw(background_, frame_fbo_, width_, height_);
}

void RangePass::draw_scene(glm::vec2 jitter) {
  const glm::mat4 view_projection =
      camera_projection_matrix(camera_, width_, height_, jitter) * camera_view_matrix(camera_);
  raster_.set("view_projection", view_projection);
  raster_.set("camera_position", glm::vec3(camera_.camera_to_world[3]));
  raster_.set("camera_forward", -glm::normalize(glm::vec3(camera_.camera_to_world[2])));
  raster_.set("orthographic", camera_.orthographic ? 1 : 0);
  const float clear_color[4] = {0, 0, 0, 0};
  const float clear_distance[4] = {kBackgroundDepth, 0, 0, 0};
  const float clear_surface[4] = {0, 0, 0, 0};
  const float clear_depth = 1.0f;
  glClearNamedFramebufferfv(frame_fbo_.id(), GL_COLOR, 0, clear_color);
  glClearNamedFramebufferfv(frame_fbo_.id(), GL_COLOR, 1, clear_distance);
  glClearNamedFramebufferfv(frame_fbo_.id(), GL_COLOR, 2, clear_surface);
  glClearNamedFramebufferfv(frame_fbo_.id(), GL_DEPTH, 0, &clear_depth);
  if (environment_.valid()) draw_environment(view_projection);
  raster_.use();
  frame_fbo_.bind(width_, height_);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDisable(GL_CULL_FACE);  // the path tracer hits both sides of every triangle
  glDisable(GL_BLEND);
  static const Material kDefault;
  for (const GpuMesh& g : meshes_) {
    const Material& m = g.material >= 0 ? materials_[g.material] : kDefault;
    auto uploaded = [&](const TextureRef& r) {
      return r.valid() && r.texture < static_cast<int>(textures_.size()) && textures_[r.texture].valid();
    };
    const TextureRef& ref = m.base_color_texture;
    raster_.bind(0, uploaded(ref) ? textures_[ref.texture] : white_);
    raster_.set("base_color", m.base_color);
    raster_.set("texcoord", ref.texcoord);
    raster_.set("uv_transform", ref.transform);
    // The path tracer maps normals only where the mesh has tangents (the loader adds them).
    const TextureRef& nref = m.normal_texture;
    const bool normal_map = uploaded(nref) && g.has_tangents;
    raster_.bind(1, normal_map ? textures_[nref.texture] : white_);
    raster_.set("normal_map", normal_map ? 1 : 0);
    raster_.set("normal_scale", m.normal_scale);
    raster_.set("normal_texcoord", nref.texcoord);
    raster_.set("normal_uv_transform", nref.transform);
    const TextureRef& rref = m.metallic_roughness_texture;
    raster_.bind(2, uploaded(rref) ? textures_[rref.texture] : white_);
    raster_.set("roughness", m.roughness);
    raster_.set("roughness_texcoord", rref.texcoord);
    raster_.set("roughness_uv_transform", rref.transform);
    // The guide is deterministic: it sees a BLEND surface where its opacity is at least one half
    // (where the path tracer's stochastic transparency keeps most hits).
    raster_.set("alpha_mask", m.alpha_mode != AlphaMode::Opaque ? 1 : 0);
    raster_.set("alpha_cutoff", m.alpha_mode == AlphaMode::Blend ? 0.5f : m.alpha_cutoff);
    raster_.set("double_sided", m.double_sided ? 1 : 0);
    raster_.set("specular", material_is_perfect_specular(m) ? 1.0f : 0.0f);
    g.vao.bind();
    raster_.require_inputs();
    glDrawElements(GL_TRIANGLES, g.index_count, GL_UNSIGNED_INT, nullptr);
  }
  glDisable(GL_DEPTH_TEST);
}

bool RangePass::step(const ChainTracer& tracer) {
  if (!begin_frame()) return false;
  std::vector<uint32_t> pixels = specular_pixels();
  if (!pixels.empty() && tracer) apply_specular_chains(pixels, tracer(pixels, jitter()));
  end_frame();
  return true;
}

bool RangePass::begin_frame() {
  if (converged_) return false;
  if (!has_camera_) throw Error("range pass: no camera set");
  timer_.begin();
  draw_scene(jitter());
  return true;
}

std::vector<uint32_t> RangePass::specular_pixels() {
  std::vector<uint32_t> pixels;
  if (!has_specular_material_) return pixels;  // nothing to read back
  reduction_.run(frame_color_, 2);  // count flagged pixels on the GPU first
  if (!(reduction_.read_sum() > 0.5f)) return pixels;
  Image flags = frame_color_.download({"R", "G", "B", "A"});
  for (size_t i = 0; i < flags.pixel_count(); ++i)
    if (flags.pixels[4 * i + 3] > 0.5f) pixels.push_back(static_cast<uint32_t>(i));
  return pixels;
}

void RangePass::apply_specular_chains(const std::vector<uint32_t>& pixels, const std::vector<SpecularChainHit>& hits) {
  if (pixels.empty()) return;
  if (hits.size() != pixels.size()) throw Error("range pass: specular chain results do not match the pixels");
  constexpr int kFloats = 10;  // pixel, color + distance, normal + roughness
  std::vector<float> data(pixels.size() * kFloats);
  for (size_t i = 0; i < pixels.size(); ++i) {
    float* d = &data[kFloats * i];
    d[0] = static_cast<float>(pixels[i] % width_);
    d[1] = static_cast<float>(pixels[i] / width_);
    const SpecularChainHit& h = hits[i];
    d[2] = h.range_color.x, d[3] = h.range_color.y, d[4] = h.range_color.z;
    d[5] = h.hit ? h.distance : kBackgroundDepth;
    const glm::vec3 n = h.hit ? h.normal : glm::vec3(0.0f);
    d[6] = n.x, d[7] = n.y, d[8] = n.z;
    d[9] = h.hit ? h.roughness : 0.0f;
  }
  point_buffer_.upload(data.data(), data.size() * sizeof(float));
  point_vao_.attribute(0, point_buffer_, 2, kFloats * sizeof(float), 0);
  point_vao_.attribute(1, point_buffer_, 4, kFloats * sizeof(float), 2 * sizeof(float));
  point_vao_.attribute(2, point_buffer_, 4, kFloats * sizeof(float), 6 * sizeof(float));
  points_.set("size", glm::vec2(width_, height_));
  points_.use();
  frame_fbo_.bind(width_, height_);
  glDisable(GL_DEPTH_TEST);
  point_vao_.bind();
  points_.require_inputs();
  glDrawArrays(GL_POINTS, 0, static_cast<GLsizei>(pixels.size()));
}

void RangePass::end_frame() {
  if (frames_ == 0) last_change_ = 1.0f;
  const int next = 1 - current_;  // ping-pong: never sample the texture being written
  accumulate_.set("count", frames_ + 1);
  accumulate_.use();
  accumulate_.bind(0, frame_color_);
  accumulate_.bind(1, frame_distance_);
  accumulate_.bind(2, guide_[current_]);
  accumulate_.bind(3, frame_surface_);
  accumulate_.bind(4, surface_[current_]);
  quad_.draw(accumulate_, accum_fbo_[next], width_, height_);
  current_ = next;
  ++frames_;
  // The change is only needed once min_frames are in (its GPU reduction costs about a raster).
  if (frames_ >= settings_.min_frames) {
    reduction_.run(change_, 0);
    last_change_ = reduction_.read_sum() / (static_cast<float>(width_) * height_);
  }
  converged_ = frames_ >= settings_.max_frames || (frames_ >= settings_.min_frames && last_change_ < settings_.tolerance);
  timer_.end();
  check_gl_error("range pass");
}

const Texture2D& RangePass::guide() const { return guide_[current_]; }

Image RangePass::range_color_image() const { return guide().download({"R", "G", "B"}); }

const Texture2D& RangePass::surface() const { return surface_[current_]; }

Image RangePass::surface_image() const { return surface().download({"X", "Y", "Z", "R"}); }

Image RangePass::depth_image() const {
  Image rgba = guide().download({"R", "G", "B", "A"});
  Image out = Image::gray(width_, height_);
  for (size_t i = 0; i < out.pixel_count(); ++i) out.pixels[i] = rgba.pixels[4 * i + 3];
  return out;
}

Image RangePass::frame_color_image() const { return frame_color_.download({"R", "G", "B"}); }

Image RangePass::specular_mask_image() const {
  Image rgba = frame_color_.download({"R", "G", "B", "A"});
  Image out = Image::gray(width_, height_);
  for (size_t i = 0; i < out.pixel_count(); ++i) out.pixels[i] = rgba.pixels[4 * i + 3];
  return out;
}

}  // namespace pxf
