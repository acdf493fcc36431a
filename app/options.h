// Options shared by `pxf render`, `pxf bench` and `pxf explore`: one declaration, one meaning.
#pragma once
#include <string>

#include "app/cli.h"
#include "gl/resources.h"
#include "pathtracer/pathtracer.h"
#include "preview/preview.h"
#include "scene/load.h"
#include "scene/scene.h"

namespace pxf {

struct SceneOptions {
  std::string scene = "cornell";  // built-in name or glTF path; "list" prints the built-ins
  std::string env;                // equirect EXR or .hdr replacing the scene's environment
  float env_strength = 1.0f;
  std::string default_light = "sky";  // default_light_names(): lights a scene that has no light
  int width = 0, height = 0;      // 0 = the scene's default, else 512x512
  std::string gl = "auto";
  // How GL stages are timed (gl/resources.h): submit, no stall per stage, for rendering; pxf bench
  // sets finish before binding the options. Applied by set_gl_timing when the command starts.
  GlTiming stage_timing = GlTiming::Submit;
  int max_texture_size = LoadLimits::kDefaultMaxTextureSize;
  int max_triangles = static_cast<int>(LoadLimits::kDefaultMaxTriangles);
};

// The loader's limits from the scene options (memory: what the system reports).
LoadLimits load_limits(const SceneOptions& options);

// The filter of an all-HV render (--all-hv, or a glTF whose extras ask for it) and of a scene lit
// mostly by its environment (at least half of the light sampler's power estimate), unless --filter
// is given. There HV holds the
// direct light too, so textured and glossy detail is filtered, and the grid's range axis (luminance
// only) averages detail that differs in luminance by less than sigma_c and shows its cells as
// blocks; a-trous weighs the RGB range color and the surface, and kept the detail where the grid
// blurred it (docs/measurements.md, "Environment-lit scenes").
constexpr FilterKind kAllHvFilter = FilterKind::Atrous;
// Whether a scene's render takes kAllHvFilter when --filter is not given.
bool takes_all_hv_filter(const Scene& scene, const PreviewSettings& settings);

void add_scene_options(CommandLine& cli, SceneOptions& options, bool headless);
// Binds the command line to the one PreviewSettings (enums through their name tables).
void add_preview_options(CommandLine& cli, PreviewSettings& settings);

// Prints the built-in scenes when options.scene == "list" (returns true: nothing else to do).
bool print_scene_list_if_asked(const SceneOptions& options);
// Loads the scene, applies its render defaults (size, all_hv unless given on the command line, and
// then kAllHvFilter where takes_all_hv_filter, unless --filter is given).
Scene load_scene_for(SceneOptions& options, PreviewSettings& settings, const CommandLine& cli);
// Prints the scene's notes and warnings to stderr, one "pxf: ..." line each.
void print_scene_messages(const Scene& scene);

}  // namespace pxf
