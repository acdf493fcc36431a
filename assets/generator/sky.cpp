#include "sky.h"

#include <algorithm>
#include <cmath>
#include <glm/gtc/constants.hpp>

namespace pxf::scenegen {

Image paint_equirect(int width, int height, const std::function<glm::vec3(const glm::vec3&)>& radiance) {
  Image image = Image::rgb(width, height);
  for (int j = 0; j < height; ++j) {
    const float theta = (j + 0.5f) / height * glm::pi<float>();
    for (int i = 0; i < width; ++i) {
      // Inverse of u = 0.5 + atan2(d.x, -d.z) / (2 pi), v = acos(d.y) / pi.
      const float phi = ((i + 0.5f) / width - 0.5f) * glm::two_pi<float>();
      const glm::vec3 d(std::sin(theta) * std::sin(phi), std::cos(theta), -std::sin(theta) * std::cos(phi));
      const glm::vec3 value = radiance(d);
      image.at(i, j, 0) = value.r, image.at(i, j, 1) = value.g, image.at(i, j, 2) = value.b;
    }
  }
  return image;
}

glm::vec3 daylight_radiance(const DaylightSky& sky, const glm::vec3& d) {
  const glm::vec3 to_sun = -glm::normalize(sky.sun_direction);
  const float angle = std::acos(std::clamp(glm::dot(d, to_sun), -1.0f, 1.0f));
  if (d.y < 0.0f) {
    // Ground: a haze band at the horizon fading into the ground's own colour.
    const float t = std::min(1.0f, -d.y * 8.0f);
    return glm::mix(sky.horizon * 0.7f, sky.ground, t);
  }
  const float t = std::pow(1.0f - d.y, 3.0f);
  glm::vec3 radiance = glm::mix(sky.zenith, sky.horizon, t);
  radiance += glm::vec3(1.0f, 0.9f, 0.7f) * (2.0f * std::exp(-angle * angle / 0.01f) + 0.25f * std::exp(-angle * angle / 0.25f));
  if (sky.clouds > 0.0f) {
    // Clouds on a dome: coordinates from azimuth (periodic) and elevation, stretched near the horizon.
    const float u = 0.5f + std::atan2(d.x, -d.z) / glm::two_pi<float>();
    const float elevation = std::asin(std::clamp(d.y, 0.0f, 1.0f)) / glm::half_pi<float>();
    const float v = std::sqrt(elevation);
    const float density = tileable_fbm(u - std::floor(u), v * 0.5f, 6, 6, 0.55f, sky.seed);
    const float cover = std::clamp((density - (1.0f - sky.clouds)) / 0.15f, 0.0f, 1.0f) * std::min(1.0f, d.y * 12.0f);
    const float lit = 0.6f + 0.4f * std::max(0.0f, glm::dot(d, to_sun));
    const glm::vec3 cloud = glm::vec3(1.3f, 1.3f, 1.35f) * lit * (0.7f + 0.3f * tileable_fbm(u - std::floor(u), v * 0.5f, 24, 3, 0.5f, sky.seed + 5));
    radiance = glm::mix(radiance, cloud, cover * 0.9f);
  }
  if (angle < sky.sun_radius * 1.05f) {
    // The disc, antialiased over 5 % of its radius, with limb darkening 1 - 0.6 (1 - mu).
    const float r = angle / sky.sun_radius;
    const float edge = std::clamp((1.05f - r) / 0.1f, 0.0f, 1.0f);
    const float mu = std::sqrt(std::max(0.0f, 1.0f - std::min(1.0f, r) * std::min(1.0f, r)));
    radiance += sky.sun_radiance * edge * (1.0f - 0.6f * (1.0f - mu));
  }
  return radiance;
}

}  // namespace pxf::scenegen
