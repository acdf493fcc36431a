// Camera-path files (app/camera_path.h): parse_camera_path, then check_path_cameras over a base
// camera, as `pxf render --camera-path FILE` does before any tracing. A path that passes the check
// must give a finite camera, within the coordinate bound, at every frame it has (sampled: the first,
// the last and up to 256 between).
#include <cmath>
#include <string>

#include "app/camera_path.h"
#include "core/error.h"
#include "fuzz/fuzz_target.h"

namespace {
bool finite_within(const glm::mat4& m) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(m[c][r]) || std::fabs(m[c][r]) > 2.0 * pxf::kMaxPathCoordinate) return false;
  return true;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const pxf::CameraPath path = pxf::parse_camera_path(text, "fuzz.json");
    const pxf::Camera base;
    pxf::check_path_cameras(path, base, "fuzz.json");
    const int frames = path.frame_count();
    const int step = frames > 256 ? frames / 256 : 1;
    for (int f = 0; f < frames; f += step) {
      const pxf::Camera camera = pxf::camera_on_path(path, f, base);
      pxf::fuzz::check(finite_within(camera.camera_to_world), "a checked path gives a non-finite or far camera");
      pxf::fuzz::check(std::isfinite(camera.yfov) && camera.yfov > 0.0f && camera.yfov < 3.1416f,
                       "a checked path gives a field of view outside (0, pi)");
    }
    const pxf::Camera last = pxf::camera_on_path(path, frames - 1, base);
    pxf::fuzz::check(finite_within(last.camera_to_world), "the last camera of a checked path is non-finite or far");
  } catch (const pxf::Error&) {
  }
  return 0;
}
