// Camera paths: keyframes of position, target and vertical field of view, each with the
// frames to the next keyframe, interpolated linearly or by a Catmull-Rom spline. Read from JSON:
//   {"interpolation": "spline",                       // or "linear" (the default)
//    "keyframes": [{"position": [0, 1, 4], "target": [0, 1, 0], "fov": 40, "frames": 30},
//                  {"position": [4, 1, 0], "target": [0, 1, 0], "fov": 40}]}
// "fov" in degrees, optional (the scene camera's); "frames" is required on every keyframe but the
// last. The path has sum(frames) + 1 frames: frame 0 is the first keyframe, the last the last one.
// `pxf render --camera-path turntable:N` is a turntable of N frames around the scene (turntable_path).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace pxf {

struct CameraKeyframe {
  glm::vec3 position{0.0f};
  glm::vec3 target{0.0f, 0.0f, -1.0f};
  float fov_degrees = 0.0f;  // 0: the base camera's
  int frames = 0;            // frames from this keyframe to the next (0 on the last)
};

struct CameraPath {
  std::vector<CameraKeyframe> keyframes;
  bool spline = false;
  int frame_count() const;  // sum of frames + 1
};

// Throws pxf::Error, one line naming `source` and what is wrong (malformed JSON, a missing or
// non-finite field, fewer than two keyframes, position == target, fov outside (0, 180), frames
// outside [1, kMaxPathFrames] or a total above it).
CameraPath parse_camera_path(const std::string& json_text, const std::string& source);
// Through the one input reader (image/input_file.h), at most kMaxPathFileBytes, JSON nested at most
// kMaxJsonDepth levels; the same refusals.
CameraPath read_camera_path(const std::string& file);
constexpr int kMaxPathFrames = 100000;
constexpr uint64_t kMaxPathFileBytes = 64ull << 20;  // 100,000 keyframes of about 100 bytes, and room
// Every camera position and target of a path, as the scene's cameras (docs/robustness.md, "Scenes").
constexpr double kMaxPathCoordinate = 1e12;

// Checks the camera of every frame of `path` over `base` as the scene's cameras are checked: finite,
// within +-kMaxPathCoordinate, position and target apart, a finite camera frame. Throws pxf::Error,
// one line naming `source`, the frame and the problem.
void check_path_cameras(const CameraPath& path, const Camera& base, const std::string& source);

// A full turn of `frames` frames around the scene's bounds center, at the scene camera's distance
// from it and height above it (looking at the center), one keyframe a frame.
CameraPath turntable_path(const Scene& scene, int frames);
// "turntable:N" -> turntable_path(scene, N); anything else is a file; then check_path_cameras.
// Throws UsageError for a bad N, pxf::Error for a bad file or camera.
CameraPath camera_path_for(const std::string& spec, const Scene& scene);

// The camera of frame `frame` (0 .. frame_count() - 1): `base` (the scene's camera, for its
// near/far planes and projection) placed at the interpolated position, looking at the target, up
// +y (+z when looking straight up or down).
Camera camera_on_path(const CameraPath& path, int frame, const Camera& base);

}  // namespace pxf
