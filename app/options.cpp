#include "app/options.h"

#include <cstdio>
#include <string>

#include "gl/context.h"
#include "pathtracer/pathtracer.h"
#include "preview/setting_table.h"
#include "scene/auto_camera.h"

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

namespace {
// The default a help line shows: the command's own, the value its settings hold before the command
// line is parsed.
std::string default_text(const SettingDescriptor& d, const PreviewSettings& defaults) {
  const nlohmann::json value = d.to_json(defaults);
  if (value.is_boolean()) return value.get<bool>() ? "on" : "off";
  if (value.is_string()) return value.get<std::string>();
  if (value.is_number_float()) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%g", value.get<double>());
    return buffer;
  }
  return value.dump();
}
}  // namespace

void add_preview_options(CommandLine& cli, PreviewSettings& s) {
  for (const SettingDescriptor& d : setting_table()) {
    const std::string help = d.help + (d.bare_flag ? "" : " (default " + default_text(d, s) + ")");
    switch (d.type) {
      case SettingType::Float: cli.option(d.flag, &d.float_field(s), help, static_cast<float>(d.min), static_cast<float>(d.max)); break;
      case SettingType::Int: cli.option(d.flag, &d.int_field(s), help, static_cast<int>(d.min), static_cast<int>(d.max)); break;
      case SettingType::Seed:
        cli.option(d.flag, &d.seed_field(s), help, static_cast<uint64_t>(d.min), static_cast<uint64_t>(d.max));
        break;
      case SettingType::Switch:
        if (d.bare_flag)
          cli.flag(d.flag, &d.switch_field(s), help);
        else
          cli.choice(d.flag, &d.switch_field(s), *d.names, help);
        break;
      case SettingType::Choice: {
        const SettingDescriptor* descriptor = &d;
        cli.choice_setter(d.flag, [descriptor, &s](size_t i) { descriptor->set_choice_index(s, i); }, *d.names, help);
        break;
      }
    }
  }
}

bool print_scene_list_if_asked(const SceneOptions& options) {
  if (options.scene != "list") return false;
  std::printf("built-in scenes (in %s):\n", builtin_assets_dir().c_str());
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
  if (takes_all_hv_filter(scene, settings) && !cli.given("--filter")) {
    settings.filter.kind = kAllHvFilter;
    std::fprintf(stderr, "pxf: %s: filter %s (--filter to choose another)\n",
                 settings.trace.all_hv ? "all-HV scene" : "lit mostly by its environment", filter_kind_name(kAllHvFilter));
  }
  return scene;
}

bool takes_all_hv_filter(const Scene& scene, const PreviewSettings& settings) {
  return settings.trace.all_hv || environment_light_share(scene) >= 0.5f;
}

}  // namespace pxf
