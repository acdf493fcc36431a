// glTF/GLB from memory through the whole scene set-up: the loader (load_scene_from_memory), the
// Embree BVH build and light set-up of a ProgressiveRenderer, and one traced frame of a 4x4 image.
// Relative uris resolve against a folder that does not exist, so external buffers and images fail
// the way missing files do; data: uris and GLB chunks are read.
#include <cmath>
#include <vector>

#include "fuzz/fuzz_target.h"
#include "pathtracer/pathtracer.h"
#include "scene/load.h"

namespace {
constexpr int kSide = 4;
// Tracing is skipped for scenes this large: the loader and the BVH are what this harness is for.
constexpr size_t kMaxTracedTriangles = 1 << 14;

bool finite(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::vector<unsigned char> bytes(data, data + size);
  try {
    const pxf::Scene scene = pxf::load_scene_from_memory(bytes, "fuzz.glb", "/nonexistent-pxf-fuzz-folder");
    pxf::TraceParams params;
    params.threads = 1;
    pxf::ProgressiveRenderer renderer(scene, params, kSide, kSide);
    if (scene.triangle_count() > kMaxTracedTriangles) return 0;
    renderer.add_frame();
    const pxf::Accumulation& acc = renderer.accumulation();
    for (size_t p = 0; p < acc.samples.size(); ++p) {
      pxf::fuzz::check(finite(acc.lv_mean[p]) && finite(acc.hv_mean[p]), "a non-finite mean radiance");
      pxf::fuzz::check(std::isfinite(acc.hv_lum_mean[p]) && std::isfinite(acc.hv_lum_m2[p]), "a non-finite Welford state");
    }
  } catch (const pxf::Error&) {
  }
  return 0;
}
