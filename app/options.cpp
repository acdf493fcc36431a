#include "app/options.h"

#include <cstdio>

#include "gl/context.h"
#include "pathtracer/auto_camera.h"
#include "pathtracer/pathtracer.h"

namespace pxf {

void add_scene_options(CommandLine& cli, SceneOptions& o, bool headless) {
  cli.option("--scene", &o.scene, "NAME|FILE.gltf", "built-in scene name, a .gltf/.glb file, or 'list' (default cornell)");
  cli.option("--env", &o.env, "FILE.exr|FILE.hdr", "equirectangular environment map (OpenEXR or Radiance) replacing the scene's");
  cli.choice("--default-light", &o.default_light, default_light_names(),
             "environment for a scene without lights: sky (default), studio, none (black)");
  cli.option("--env-strength", &o.env_strength, "environment radiance scale", 0.0f, 1e6f);
  cli.size_option("--size", &o.width, &o.height, "image size (default: the scene's, else 512x512)");
  cli.option("--max-texture-size", &o.max_texture_size,
             "refuse scenes with a texture wider or taller than this many texels (default 16384)", 1, 1 << 30);
  cli.option("--max-triangles", &o.max_triangles,
             "refuse scenes that instance more triangles than this (default 100000000); scenes whose\n"
             "estimated memory exceeds the available memory are refused too", 1, 2147483647);
  if (headless)
    cli.choice("--gl", &o.gl, {"auto", "osmesa", "egl"}, "headless GL back end (auto: OSMesa, else EGL)");
  else
    cli.choice("--gl", &o.gl, {"auto", "window", "osmesa", "egl"}, "GL back end (auto: a window when a display exists)");
  cli.choice("--stage-timing", &o.stage_timing, gl_timing_names(),
             std::string("how the GL stages' ms are measured: finish = glFinish around each (exact, stalls),\n"
                         "submit = without (on llvmpipe nearly the same figures); default ") +
                 gl_timing_names()[static_cast<int>(o.stage_timing)]);
}

void add_preview_options(CommandLine& cli, PreviewSettings& s, bool adaptive_option) {
  cli.option("--threshold", &s.threshold, "blend threshold t on perceived variance (default 0.001)", 0.0f, 1e6f);
  cli.option("--sigma-s", &s.filter.sigma_s, "spatial sigma in pixels (default 8)", 0.1f, kMaxFilterRadius / 3.0f);
  cli.option("--sigma-c", &s.filter.sigma_c, "range color sigma, linear RGB (default 0.02)", 1e-6f, 1e6f);
  cli.option("--sigma-d", &s.filter.sigma_d, "range depth sigma, scene units (default 2)", 1e-6f, 1e6f);
  cli.choice("--filter", &s.filter.kind, filter_option_names(), "filter variant (default grid: the bilateral grid on the range luminance)");
  cli.choice("--schedule", &s.schedule, filter_schedule_names(),
             "when the filter runs: budget = at power-of-two sample counts while filter + range stay within\n"
             "10 % of the tracing time (default); pow2 = at every power of two; every = each frame; all also\n"
             "the last frame");
  cli.choice("--demodulate", &s.demodulate, {"off", "on"},
             "albedo demodulation: filter HV divided by the first non-specular albedo, so textures stay\n"
             "sharp (default off: docs/measurements.md, \"Albedo demodulation\")");
  cli.choice("--bias-guard", &s.bias_guard, {"off", "on"},
             "the blend's bias guard: where the filtered light measurably differs from the unfiltered\n"
             "(5x5 neighbours, 2 standard deviations), s is raised to the least-error blend factor (default on;\n"
             "off: the published blend, noise held at t everywhere; docs/method.md section 3.7)");
  cli.choice("--sigma-shrink", &s.shrink_sigma, {"off", "on"},
             "shrink the filter's sigma_s as samples accumulate: --sigma-s up to 4 spp, then\n"
             "sigma_s sqrt(4 / spp), at least 2 px (default off: --sigma-s for every filter run; on lowers\n"
             "the error but mixed pixels keep more noise than t, docs/method.md 2.5)");
  cli.choice("--motion-history", &s.motion_history, {"off", "on"},
             "after a camera move, reproject what the view showed into the new view beside the fresh samples,\n"
             "its weight falling to 0 over 16 samples (default on; off: a move restarts from nothing;\n"
             "docs/method.md 4.1)");
  if (adaptive_option)
    cli.choice("--adaptive", &s.adaptive, {"off", "on"},
               "adaptive sampling: after 16 uniform frames each frame traces the pixels whose final pixel is\n"
               "furthest from the threshold, every pixel at least every 16 frames (default off; app/adaptive.h)");
  cli.option("--seed", &s.trace.seed, "random seed", 0, 2147483647);
  cli.choice("--sampler", &s.trace.sampler, sampler_type_names(),
             "random numbers of the path tracer: Owen-scrambled Sobol (default) or independent PCG32");
  cli.option("--replicates", &s.trace.replicates,
             "independently scrambled Sobol replicates for the variance estimate (default 1 = none)", 1, 64);
  cli.option("--threads", &s.trace.threads, "path-tracing threads (0 = all cores)", 0, 1024);
  cli.option("--max-vertices", &s.trace.max_vertices, "maximum path length in vertices, camera and light included", 2, 1024);
  cli.option("--rr-start", &s.trace.rr_start_vertex, "Russian roulette from this vertex on", 2, 1024);
  cli.flag("--specular-sampling", &s.trace.specular_sampling,
           "also sample the cones of mirror and glass objects at diffuse vertices, MIS-combined with BSDF\n"
           "sampling: unbiased, fewer caustic fireflies, more rays (docs/sampling.md#fireflies)");
  cli.choice("--near-specular", &s.trace.near_specular_sampling, {"off", "on"},
             "the same at the first diffuse vertex only, toward mirror and glass objects that fill at least pi sr\n"
             "of its view: the focus a glass object throws on the floor it stands on (default on;\n"
             "docs/sampling.md#near-specular-sampling)");
  cli.choice("--guiding", &s.trace.guiding, {"off", "on"},
             "path guiding: learn where indirect light comes from (an SD-tree, Mueller et al. 2017) and send\n"
             "half of the diffuse and glossy directions there, MIS-combined with BSDF sampling: unbiased\n"
             "(default off; docs/guiding.md)");
  cli.flag("--all-hv", &s.trace.all_hv, "put every contribution into the HV buffer but what the camera sees directly or through\nmirrors and glass (environment-lit scenes)");
  cli.option("--key", &s.tonemap.key, "Reinhard key a (default 0.18)", 1e-4f, 100.0f);
  cli.option("--white", &s.tonemap.white, "Reinhard white point (0 = none)", 0.0f, 1e9f);
}

bool print_scene_list_if_asked(const SceneOptions& options) {
  if (options.scene != "list") return false;
  for (const BuiltinScene& s : builtin_scenes()) std::printf("%-10s %s\n", s.name.c_str(), s.description.c_str());
  return true;
}

void print_scene_messages(const Scene& scene) {
  for (const std::string& n : scene.notes) std::fprintf(stderr, "pxf: %s\n", n.c_str());
  for (const std::string& w : scene.warnings) std::fprintf(stderr, "pxf: warning: %s\n", w.c_str());
}

LoadLimits load_limits(const SceneOptions& options) {
  LoadLimits limits;
  limits.max_texture_size = options.max_texture_size;
  limits.max_triangles = static_cast<uint64_t>(options.max_triangles);
  return limits;
}

Scene load_scene_for(SceneOptions& options, PreviewSettings& settings, const CommandLine& cli) {
  Scene scene = load_scene(options.scene, options.env, options.env_strength, parse_default_light(options.default_light),
                           load_limits(options));
  print_scene_messages(scene);
  if (options.width == 0) {
    options.width = scene.defaults.width > 0 ? scene.defaults.width : 512;
    options.height = scene.defaults.height > 0 ? scene.defaults.height : 512;
  }
  if (scene.automatic_camera) scene.camera = frame_scene(scene, static_cast<float>(options.width) / options.height);
  if (!cli.given("--all-hv") && scene.defaults.all_hv) settings.trace.all_hv = true;
  if (settings.trace.all_hv && !cli.given("--filter")) {
    settings.filter.kind = kAllHvFilter;
    std::fprintf(stderr, "pxf: all-HV (environment-lit) scene: filter %s (--filter to choose another)\n",
                 filter_kind_name(kAllHvFilter));
  }
  return scene;
}

}  // namespace pxf
