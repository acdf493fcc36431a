#include "scene/spec_gloss.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "core/parallel.h"
#include "image/image.h"
#include "scene/texture.h"

namespace pxf {

namespace {

constexpr float kDielectricF0 = 0.04f;
constexpr float kEpsilon = 1e-6f;

float perceived_brightness(glm::vec3 c) {
  return std::sqrt(0.299f * c.r * c.r + 0.587f * c.g * c.g + 0.114f * c.b * c.b);
}

// The metallic m for which a metal/dielectric mix of the given diffuse and specular brightness
// reflects the same: the positive root of 0.04 m² + b m + c = 0.
float solve_metallic(float diffuse, float specular, float one_minus_specular_strength) {
  if (specular < kDielectricF0) return 0.0f;
  const float a = kDielectricF0;
  const float b = diffuse * one_minus_specular_strength / (1.0f - kDielectricF0) + specular - 2.0f * kDielectricF0;
  const float c = kDielectricF0 - specular;
  const float d = std::max(b * b - 4.0f * a * c, 0.0f);
  return std::clamp((-b + std::sqrt(d)) / (2.0f * a), 0.0f, 1.0f);
}

uint8_t code(float v) { return static_cast<uint8_t>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f)); }

}  // namespace

MetalRough metal_rough_from_spec_gloss(glm::vec4 diffuse, glm::vec3 specular, float glossiness) {
  auto clean = [](float v) { return std::isfinite(v) ? std::clamp(v, 0.0f, 1.0f) : 0.0f; };
  for (int i = 0; i < 4; ++i) diffuse[i] = clean(diffuse[i]);
  for (int i = 0; i < 3; ++i) specular[i] = clean(specular[i]);
  glossiness = clean(glossiness);
  const glm::vec3 d(diffuse);
  const float one_minus_specular_strength = 1.0f - std::max({specular.r, specular.g, specular.b});
  MetalRough out;
  out.metallic = solve_metallic(perceived_brightness(d), perceived_brightness(specular), one_minus_specular_strength);
  const float m = out.metallic;
  const glm::vec3 from_diffuse = d * (one_minus_specular_strength / (1.0f - kDielectricF0) / std::max(1.0f - m, kEpsilon));
  const glm::vec3 from_specular = (specular - glm::vec3(kDielectricF0 * (1.0f - m))) / std::max(m, kEpsilon);
  const glm::vec3 base = glm::clamp(glm::mix(from_diffuse, from_specular, m * m), glm::vec3(0.0f), glm::vec3(1.0f));
  out.base_color = glm::vec4(base, diffuse.a);
  out.roughness = 1.0f - glossiness;
  return out;
}

BakedSpecGloss bake_spec_gloss(const Texture* diffuse, const Texture* spec_gloss, const SpecGlossFactors& factors,
                               int width, int height, const Texture& sampler) {
  width = std::max(width, 1);
  height = std::max(height, 1);
  const size_t count = static_cast<size_t>(width) * height;
  auto base = std::make_shared<std::vector<unsigned char>>(4 * count);
  auto mr = std::make_shared<std::vector<unsigned char>>(4 * count);
  parallel_for(static_cast<size_t>(height), [&](size_t row) {
    const int y = static_cast<int>(row);
    for (int x = 0; x < width; ++x) {
      const glm::vec2 uv((x + 0.5f) / width, (y + 0.5f) / height);
      const glm::vec4 dt = diffuse ? sample_texture(*diffuse, uv) : glm::vec4(1.0f);
      const glm::vec4 st = spec_gloss ? sample_texture(*spec_gloss, uv) : glm::vec4(1.0f);
      const MetalRough c =
          metal_rough_from_spec_gloss(factors.diffuse * dt, factors.specular * glm::vec3(st), factors.glossiness * st.a);
      const size_t i = 4 * (static_cast<size_t>(y) * width + x);
      for (int k = 0; k < 3; ++k) (*base)[i + k] = code(srgb_from_linear(c.base_color[k]));
      (*base)[i + 3] = code(c.base_color.a);
      (*mr)[i + 0] = 0;
      (*mr)[i + 1] = code(c.roughness);
      (*mr)[i + 2] = code(c.metallic);
      (*mr)[i + 3] = 255;
    }
  });
  BakedSpecGloss out;
  for (Texture* t : {&out.base_color, &out.metallic_roughness}) {
    t->width = width;
    t->height = height;
    t->wrap_s = sampler.wrap_s;
    t->wrap_t = sampler.wrap_t;
    t->nearest = sampler.nearest;
  }
  out.base_color.name = sampler.name + " (base color from specular-glossiness)";
  out.base_color.srgb = true;
  out.base_color.texels8 = std::move(base);
  out.metallic_roughness.name = sampler.name + " (metallic-roughness from specular-glossiness)";
  out.metallic_roughness.texels8 = std::move(mr);
  return out;
}

}  // namespace pxf
