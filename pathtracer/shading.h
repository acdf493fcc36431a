// What the integrator and the specular chains both read at a surface point: its BsdfMaterial,
// precomputed per untextured material, and whether its emission reaches the ray that found it.
#pragma once
#include <cstddef>
#include <vector>

#include <glm/glm.hpp>

#include "pathtracer/bsdf.h"
#include "pathtracer/embree_scene.h"
#include "scene/scene.h"

namespace pxf {

// Emission leaves a surface toward the ray only on its front face, unless it is double-sided.
inline bool emission_visible(const Material& material, const SurfacePoint& sp) {
  return material.is_emissive() && (sp.front_face || material.double_sided);
}

// The BsdfMaterial of every surface point of a scene.
class BsdfMaterials {
 public:
  explicit BsdfMaterials(const Scene& scene) : scene_(scene) {
    for (const Material& material : scene.materials) {
      Precomputed precomputed;
      precomputed.constant = eval_material_is_constant(material);
      if (precomputed.constant)
        precomputed.material =
            bsdf_material(eval_material(scene, material, glm::vec2(0.0f), glm::vec2(0.0f), glm::vec4(1.0f)));
      precomputed_.push_back(precomputed);
    }
  }
  // The BsdfMaterial at sp: the one precomputed for its material when eval_material() reads no
  // texture of it and the vertex color is white (base color x 1 is exact, so the values are the
  // same), else evaluated into *scratch.
  const BsdfMaterial& at(const SurfacePoint& sp, BsdfMaterial* scratch) const {
    const size_t index = static_cast<size_t>(sp.material - scene_.materials.data());
    const Precomputed& precomputed = precomputed_[index];
    if (precomputed.constant && sp.color == glm::vec4(1.0f)) return precomputed.material;
    *scratch = bsdf_material(eval_material(scene_, *sp.material, sp.uv0, sp.uv1, sp.color, sp.texture_footprint));
    return *scratch;
  }

 private:
  struct Precomputed {
    bool constant = false;  // eval_material_is_constant: `material` holds its BsdfMaterial
    BsdfMaterial material;
  };
  const Scene& scene_;
  std::vector<Precomputed> precomputed_;  // per scene material
};

}  // namespace pxf
