// Environment maps for the built-in scenes: an equirectangular painter (the mapping pxf reads,
// u = 0.5 + atan2(d.x, -d.z) / 2 pi, v = acos(d.y) / pi) and a clear or cloudy daylight sky with
// the sun as a bright disc in the map itself (for scenes lit by the environment alone).
#pragma once
#include <glm/glm.hpp>
#include <cstdint>
#include <functional>

#include "texture.h"

namespace pxf::scenegen {

// An RGB equirectangular image of `radiance(direction)` sampled at the texel centres.
Image paint_equirect(int width, int height, const std::function<glm::vec3(const glm::vec3&)>& radiance);

struct DaylightSky {
  glm::vec3 sun_direction{0.0f, -1.0f, 0.0f};  // where sunlight travels (towards the scene)
  float sun_radius = 0.025f;                    // angular radius of the disc, radians
  glm::vec3 sun_radiance{16000.0f, 15000.0f, 13000.0f};  // at the disc's centre (the limb is darker)
  glm::vec3 zenith{0.25f, 0.45f, 0.95f};
  glm::vec3 horizon{0.85f, 0.92f, 1.05f};
  glm::vec3 ground{0.45f, 0.42f, 0.36f};  // below the horizon: sunlit ground seen from afar
  float clouds = 0.0f;                    // cloud cover, 0 (clear) to about 0.6
  uint32_t seed = 1;
};

// Radiance of `sky` towards `d` (unit vector): a zenith-horizon gradient with a circumsolar glow,
// fbm clouds (tileable in azimuth, so no seam at the map's edge), a ground below the horizon and
// the sun's disc with a darkened limb.
glm::vec3 daylight_radiance(const DaylightSky& sky, const glm::vec3& d);

}  // namespace pxf::scenegen
