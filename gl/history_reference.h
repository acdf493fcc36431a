// Plain C++ implementation of the history passes (gl/history_pass.h) on pxf::Image: the reference
// the GL shaders are tested against, from the same formulas (shaders/history_formulas.h).
// Images: "R,G,B,A" each, as the GL textures hold them: previous L_lv with the samples it holds in
// A, L_u with Var[L_u] in A, guides with the distance in A; the fresh L_lv with the threshold factor in A.
#pragma once
#include "image/image.h"
#include "scene/scene.h"

namespace pxf {

struct HistoryReprojection {
  Image lv;       // "R,G,B,A": L_lv, samples held (0: no history)
  Image hv;       // "R,G,B,A": L_u, Var[L_u]
  Image outcome;  // "Y": kHistory*
};
// previous_specular, specular: "Y" 1 where the view's surface is perfectly specular (nullptr: none).
HistoryReprojection cpu_reproject_history(const Image& previous_lv, const Image& previous_hv,
                                          const Image& previous_guide, const Camera& previous_camera,
                                          const Image& guide, const Camera& camera,
                                          const Image* previous_specular = nullptr, const Image* specular = nullptr);

struct HistoryCombination {
  Image lv;      // "R,G,B,A": the L_lv the passes read, the fresh threshold factor
  Image hv;      // "R,G,B,A": L_u, Var[L_u]
  Image state;   // "R,G,B,A": L_lv, the samples it counts as
  Image weight;  // "Y": the history's weight
};
// history == nullptr: the fresh samples alone.
HistoryCombination cpu_combine_history(const Image& lv, const Image& hv, float samples,
                                       const HistoryReprojection* history);

}  // namespace pxf
