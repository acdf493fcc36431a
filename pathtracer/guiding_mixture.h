// The BSDF-side strategy of a path vertex, which next event estimation and the specular chains
// weigh their samples against by MIS.
#pragma once
#include <glm/glm.hpp>

#include "pathtracer/guiding_field.h"

namespace pxf {

// BSDF sampling alone (not guided), or with path guiding the one-sample mixture that picks the
// guided direction with probability alpha.
struct GuidingMixture {
  bool guided = false;
  GuidingField::Distribution guide;  // the field's at the vertex, when guided
  float alpha = 0.0f;
  // The solid-angle pdf of direction wi under the strategy, given the BSDF's own pdf of it.
  float pdf(float bsdf_pdf, glm::vec3 wi) const {
    return guided ? alpha * guide.pdf(wi) + (1.0f - alpha) * bsdf_pdf : bsdf_pdf;
  }
};

}  // namespace pxf
