// G-buffer/range pass (docs/method.md section 1.2): rasterizes the scene with the path tracer's exact camera into a
// noise-free guide (range color + distance) and surface buffer (shading normal + roughness), antialiased by accumulating jittered frames
// (raster_jitter(k)) until the mean per-pixel change drops below a tolerance or a frame cap.
// Re-rendered only when the camera or the scene changes.
// Usage (with a path tracer for the perfectly specular pixels):
//   RangePass range(w, h);
//   range.set_scene(scene);  range.set_camera(camera);   // set_camera is a no-op if unchanged
//   while (!range.converged())   // or one step per displayed frame
//     range.step([&](const std::vector<uint32_t>& px, glm::vec2 jitter) {
//       return renderer.trace_specular_chains(px, jitter); });
//   filter.run(inputs, range.guide(), ...);
// step() = begin_frame(); if specular pixels are visible: specular_pixels(),
// apply_specular_chains(); end_frame(). Without visible perfect specular surfaces (the common
// case) no read-back and no callback happen.
#pragma once
#include <cstdint>
#include <functional>
#include <vector>
#include "gl/reduction.h"
#include "gl/resources.h"
#include "scene/range.h"
#include "scene/scene.h"

namespace pxf {

struct RangeSettings {
  int max_frames = 32;      // frame cap of the accumulation
  int min_frames = 8;        // so that the jitter sequence's mean is near the pixel center
  // The mean over pixels of the per-frame change (color, relative distance) below which the
  // accumulation has converged; the change decays about as 1/frames where there are edges.
  float tolerance = 5e-4f;
};

class RangePass {
 public:
  RangePass(int width, int height);
  ~RangePass();

  // Uploads meshes + base color textures; marks dirty; takes scene.camera when none is set yet.
  void set_scene(const Scene& scene);
  void set_camera(const Camera& camera); // marks dirty when it differs from the current one
  void set_settings(const RangeSettings& settings) { settings_ = settings; }
  void invalidate() { frames_ = 0; converged_ = false; }  // restart the accumulation

  bool converged() const { return converged_; }
  int frames() const { return frames_; }            // accumulated frames
  float last_change() const { return last_change_; }
  double last_ms() const { return timer_.last_ms(); }  // the last step (raster + accumulate)

  using ChainTracer = std::function<std::vector<SpecularChainHit>(const std::vector<uint32_t>& pixels, glm::vec2 jitter)>;
  // One antialiasing frame; no-op (returns false) once converged. tracer may be empty.
  bool step(const ChainTracer& tracer = {});

  // The pieces of step(), for callers that interleave them themselves.
  bool begin_frame();                    // rasterizes frame frames() with jitter()
  glm::vec2 jitter() const;              // of the frame begun last
  // Pixels (y * width + x) of the current frame whose visible surface is perfectly specular.
  std::vector<uint32_t> specular_pixels();
  // Overrides color, distance and surface of those pixels in the current frame (hit = false: color
  // 0, distance kBackgroundDepth, normal 0: unknown).
  void apply_specular_chains(const std::vector<uint32_t>& pixels, const std::vector<SpecularChainHit>& hits);
  void end_frame();                      // accumulates, updates converged()

  const Texture2D& guide() const;        // rgb range color, a distance (antialiased)
  // xyz the shading normal (normal map applied, flipped toward the viewer for double-sided
  // materials; 0 where unknown: the environment, an escaped specular chain), w the roughness;
  // averaged over the antialiasing frames like the guide. Perfectly specular pixels hold their
  // chain's end.
  const Texture2D& surface() const;
  Image surface_image() const;           // "X,Y,Z,R": normal, roughness
  // The newest frame's raster output: rgb its range color, a 1 where its surface is perfectly
  // specular (the guide's distance there is a specular chain's, not the distance to a surface).
  const Texture2D& frame_color() const { return frame_color_; }
  Image range_color_image() const;       // "R,G,B"
  Image depth_image() const;             // "Y": distance
  Image frame_color_image() const;       // the current (single) frame, "R,G,B"
  Image specular_mask_image() const;     // "Y": the current frame's specular flag

 private:
  struct GpuMesh;
  void draw_scene(glm::vec2 jitter);
  void upload_environment(const Scene& scene);
  void draw_environment(const glm::mat4& view_projection);  // where camera rays escape
  int width_, height_;
  Program raster_, points_, accumulate_, background_;
  Texture2D frame_color_, frame_distance_, frame_surface_, frame_depth_, guide_[2], surface_[2], change_;
  Framebuffer frame_fbo_, accum_fbo_[2];
  FullscreenPass quad_;
  GpuReduction reduction_;
  std::vector<GpuMesh> meshes_;
  std::vector<Texture2D> textures_;
  Texture2D white_;
  Texture2D environment_;  // equirect radiance; invalid when the scene has none
  float environment_strength_ = 0.0f;
  std::vector<Material> materials_;
  bool has_specular_material_ = false;
  Camera camera_;
  bool has_camera_ = false;
  Buffer point_buffer_;
  VertexArray point_vao_;
  RangeSettings settings_;
  int frames_ = 0;
  int current_ = 0;  // guide_[current_] holds the accumulation
  bool converged_ = false;
  float last_change_ = 0;
  StageTimer timer_;
};

}  // namespace pxf
