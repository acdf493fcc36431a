// The camera a scene without one gets: it frames the model's bounding box.
#pragma once
#include <glm/glm.hpp>

#include "scene/scene.h"

namespace pxf {

// A perspective camera (Camera's default yfov) looking at the box [lo, hi] from a three-quarter
// view: from the front (+Z, the side a glTF model faces), right and above, at the azimuth
// (20..70 degrees off +Z) and elevation (15..50 degrees) that show the box's largest projected
// area, so that a flat model is seen from above at an angle and a rod from its side. The box's
// projection is centered and fills `fill` of the frame along its tighter axis, for an image of
// width / height = `aspect` (and stays inside the frame at any wider aspect).
Camera frame_bounds(glm::vec3 lo, glm::vec3 hi, float aspect = 1.0f, float fill = 0.9f);

// frame_bounds of the scene's triangles (a unit box at the origin when there are none).
Camera frame_scene(const Scene& scene, float aspect = 1.0f);

// The box's projected area seen along the unit direction `d` (orthographic projection).
float projected_box_area(glm::vec3 size, glm::vec3 d);

}  // namespace pxf
