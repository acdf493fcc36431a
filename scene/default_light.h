// The built-in environment that lights a scene which brings no light of its own (a bare model
// exported without lamps): generated in code, no file. Shared by `pxf render`, `bench` and
// `explore` through load_scene.
#pragma once
#include <string>
#include <vector>

#include "scene/scene.h"

namespace pxf {

enum class DefaultLight { Sky, Studio, None };

// Option names in DefaultLight order ("sky", "studio", "none"): one table for the CLI and the explorer.
const std::vector<std::string>& default_light_names();
DefaultLight parse_default_light(const std::string& name);  // throws pxf::Error on an unknown name
const std::string& default_light_name(DefaultLight light);

// True when the scene can light itself: a punctual light, an environment, or an emissive material
// whose emission is not texture-modulated. Textured emission (the LEDs of a helmet, a screen) is
// decoration that lights nothing around it, so a scene with only that still gets the default light.
bool scene_has_light(const Scene& scene);

// A neutral equirectangular environment (Environment's lat-long convention):
//  sky    — overcast sky brighter towards the zenith, a soft sun above the front left, grey ground;
//  studio — dark grey surround, a large key softbox above the front left, a weaker fill on the
//           right, a rim strip behind, a dark floor.
// Both give an upward white Lambert surface an irradiance of about pi (radiance of order 1).
Environment make_default_environment(DefaultLight light);

// Applies the default light: when the scene has no light and `light` is not None, sets the
// environment and returns the line to print ("no lights in the scene: lit by ..."); with None it
// returns the warning that the image will be black; "" when the scene has its own light.
std::string apply_default_light(Scene& scene, DefaultLight light);

}  // namespace pxf
