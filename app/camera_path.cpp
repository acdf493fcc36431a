#include "app/camera_path.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>

#include "app/cli.h"
#include "scene/camera_controls.h"
#include "core/error.h"
#include "core/json_depth.h"
#include "image/input_file.h"

namespace pxf {

int CameraPath::frame_count() const {
  int total = 1;
  for (size_t i = 0; i + 1 < keyframes.size(); ++i) total += keyframes[i].frames;
  return total;
}

namespace {

using nlohmann::json;

[[noreturn]] void refuse(const std::string& source, const std::string& what) {
  throw Error("camera path " + source + ": " + what);
}

glm::vec3 read_point(const json& key, const char* field, const std::string& source, const std::string& where) {
  const auto it = key.find(field);
  if (it == key.end()) refuse(source, where + ": no \"" + field + "\"");
  if (!it->is_array() || it->size() != 3) refuse(source, where + ": \"" + field + "\" must be an array of 3 numbers");
  glm::vec3 p;
  for (int c = 0; c < 3; ++c) {
    const json& v = (*it)[c];
    if (!v.is_number() || !std::isfinite(v.get<double>()))
      refuse(source, where + ": \"" + field + "\" must be an array of 3 finite numbers");
    // In doubles and after narrowing: 1e300 is finite as a double and infinite as a float.
    if (!(std::abs(v.get<double>()) <= kMaxPathCoordinate) || !std::isfinite(v.get<float>()))
      refuse(source, where + ": \"" + field + "\" must lie within +-1e12");
    p[c] = v.get<float>();
  }
  return p;
}

CameraKeyframe read_keyframe(const json& key, bool last, const std::string& source, const std::string& where) {
  if (!key.is_object()) refuse(source, where + " is not an object");
  CameraKeyframe k;
  k.position = read_point(key, "position", source, where);
  k.target = read_point(key, "target", source, where);
  if (glm::length(k.target - k.position) < 1e-6f) refuse(source, where + ": \"position\" and \"target\" coincide");
  if (const auto fov = key.find("fov"); fov != key.end()) {
    if (!fov->is_number() || !(fov->get<double>() > 0.0 && fov->get<double>() < 180.0))
      refuse(source, where + ": \"fov\" must be a number of degrees in (0, 180)");
    k.fov_degrees = fov->get<float>();
  }
  const auto frames = key.find("frames");
  if (!last) {
    if (frames == key.end()) refuse(source, where + ": no \"frames\" (the frames to the next keyframe)");
    if (!frames->is_number_integer() || frames->get<long long>() < 1 || frames->get<long long>() > kMaxPathFrames)
      refuse(source, where + ": \"frames\" must be an integer in [1, " + std::to_string(kMaxPathFrames) + "]");
    k.frames = frames->get<int>();
  }
  return k;
}

// Catmull-Rom through p1 (t = 0) and p2 (t = 1), with p0 and p3 the neighbours.
glm::vec3 catmull_rom(glm::vec3 p0, glm::vec3 p1, glm::vec3 p2, glm::vec3 p3, float t) {
  const float t2 = t * t, t3 = t2 * t;
  return 0.5f * (2.0f * p1 + (p2 - p0) * t + (2.0f * p0 - 5.0f * p1 + 4.0f * p2 - p3) * t2 +
                 (3.0f * p1 - p0 - 3.0f * p2 + p3) * t3);
}

Camera look_at(const Camera& base, glm::vec3 position, glm::vec3 target, float fov_degrees) {
  Camera c = base;
  const glm::vec3 forward = glm::normalize(target - position);
  const glm::vec3 up = std::abs(forward.y) > 0.999f ? glm::vec3(0.0f, 0.0f, 1.0f) : glm::vec3(0.0f, 1.0f, 0.0f);
  c.camera_to_world = glm::inverse(glm::lookAt(position, target, up));
  if (fov_degrees > 0.0f) c.yfov = glm::radians(fov_degrees);
  return c;
}

}  // namespace

CameraPath parse_camera_path(const std::string& json_text, const std::string& source) {
  const json doc = json::parse(json_text, nullptr, /*allow_exceptions=*/false);
  if (doc.is_discarded()) refuse(source, "not valid JSON");
  if (!doc.is_object()) refuse(source, "the top level must be an object with \"keyframes\"");
  CameraPath path;
  if (const auto it = doc.find("interpolation"); it != doc.end()) {
    if (*it == "spline") path.spline = true;
    else if (*it != "linear") refuse(source, "\"interpolation\" must be \"linear\" or \"spline\"");
  }
  const auto keys = doc.find("keyframes");
  if (keys == doc.end() || !keys->is_array()) refuse(source, "no \"keyframes\" array");
  if (keys->size() < 2) refuse(source, "at least two keyframes are needed");
  long long total = 1;
  for (size_t i = 0; i < keys->size(); ++i) {
    path.keyframes.push_back(read_keyframe((*keys)[i], i + 1 == keys->size(), source, "keyframe " + std::to_string(i + 1)));
    total += path.keyframes.back().frames;
    if (total > kMaxPathFrames) refuse(source, "more than " + std::to_string(kMaxPathFrames) + " frames in all");
  }
  return path;
}

CameraPath read_camera_path(const std::string& file) {
  // The one input reader (image/input_file.h): a FIFO or /dev/zero is refused, not read.
  const std::vector<unsigned char> bytes = read_input_file(file, kMaxPathFileBytes);
  const std::string text(bytes.begin(), bytes.end());
  if (json_nesting_depth(text.data(), text.size()) > kMaxJsonDepth)
    refuse(file, "JSON nested deeper than " + std::to_string(kMaxJsonDepth) + " levels");
  return parse_camera_path(text, file);
}

CameraPath turntable_path(const Scene& scene, int frames) {
  if (frames < 1 || frames > kMaxPathFrames)
    throw Error("camera path turntable: the frame count must be in [1, " + std::to_string(kMaxPathFrames) + "]");
  const Bounds bounds = scene_bounds(scene);
  const glm::vec3 center = 0.5f * (bounds.lo + bounds.hi);
  const glm::vec3 eye = glm::vec3(scene.camera.camera_to_world[3]);
  const glm::vec2 offset(eye.x - center.x, eye.z - center.z);
  const float radius = std::max(glm::length(offset), 1e-3f);
  const float start = std::atan2(offset.y, offset.x);
  CameraPath path;
  for (int f = 0; f <= frames; ++f) {
    const float angle = start + 2.0f * 3.14159265358979f * static_cast<float>(f) / static_cast<float>(frames);
    CameraKeyframe k;
    k.position = {center.x + radius * std::cos(angle), eye.y, center.z + radius * std::sin(angle)};
    k.target = center;
    k.frames = f < frames ? 1 : 0;
    path.keyframes.push_back(k);
  }
  // N frames of a full turn: the last keyframe (back at the start) is not a frame of its own.
  path.keyframes.pop_back();
  path.keyframes.back().frames = 0;
  if (path.keyframes.size() < 2) path.keyframes.push_back(path.keyframes.back());
  return path;
}

CameraPath camera_path_for(const std::string& spec, const Scene& scene) {
  const std::string prefix = "turntable:";
  CameraPath path;
  if (spec.rfind(prefix, 0) != 0) {
    path = read_camera_path(spec);
  } else {
    // A bad N is a bad flag value (exit 2), like any other.
    const std::string count = spec.substr(prefix.size());
    char* end = nullptr;
    const long frames = std::strtol(count.c_str(), &end, 10);
    if (count.empty() || *end != '\0' || frames < 1 || frames > kMaxPathFrames)
      throw UsageError("--camera-path " + spec + ": expected turntable:N, N a frame count in [1, " +
                       std::to_string(kMaxPathFrames) + "]");
    path = turntable_path(scene, static_cast<int>(frames));
  }
  check_path_cameras(path, scene.camera, spec);
  return path;
}

namespace {

// Where a path's camera is and looks at `t` (0..1) along keyframe `segment` to the next.
struct PathPose {
  glm::vec3 position, target;
  float fov_degrees;
};

PathPose pose_in_segment(const CameraPath& path, int segment, float t, const Camera& base) {
  const std::vector<CameraKeyframe>& k = path.keyframes;
  const int last = static_cast<int>(k.size()) - 1;
  const CameraKeyframe& a = k[segment];
  const CameraKeyframe& b = k[std::min(segment + 1, last)];
  const float fov_a = a.fov_degrees > 0 ? a.fov_degrees : glm::degrees(base.yfov);
  const float fov_b = b.fov_degrees > 0 ? b.fov_degrees : glm::degrees(base.yfov);
  const float fov = fov_a + (fov_b - fov_a) * t;
  if (!path.spline) return {glm::mix(a.position, b.position, t), glm::mix(a.target, b.target, t), fov};
  const CameraKeyframe& before = k[std::max(segment - 1, 0)];
  const CameraKeyframe& after = k[std::min(segment + 2, last)];
  return {catmull_rom(before.position, a.position, b.position, after.position, t),
          catmull_rom(before.target, a.target, b.target, after.target, t), fov};
}

float segment_t(const CameraPath& path, int segment, int frame_in_segment) {
  const int frames = path.keyframes[segment].frames;
  return frames > 0 ? std::clamp(static_cast<float>(frame_in_segment) / frames, 0.0f, 1.0f) : 0.0f;
}

float largest_magnitude(glm::vec3 v) { return std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)}); }

// What is wrong with a pose as a camera (finite, within the bound, position and target apart, a
// finite frame), or "" when nothing is. The spline can leave the keyframes' bounds, and two
// keyframes can cross, so every frame is checked, not only the keyframes.
std::string pose_problem(const PathPose& pose, const Camera& base) {
  for (const glm::vec3& p : {pose.position, pose.target})
    if (!(largest_magnitude(p) <= static_cast<float>(kMaxPathCoordinate))) return "the camera leaves +-1e12";
  const float scale = std::max({1.0f, largest_magnitude(pose.position), largest_magnitude(pose.target)});
  if (!(glm::length(pose.target - pose.position) > 1e-6f * scale)) return "position and target meet";
  if (!(pose.fov_degrees > 0.0f && pose.fov_degrees < 180.0f)) return "the field of view leaves (0, 180) degrees";
  const glm::mat4 m = look_at(base, pose.position, pose.target, pose.fov_degrees).camera_to_world;
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(m[c][r])) return "the camera frame is not finite";
  return "";
}

}  // namespace

void check_path_cameras(const CameraPath& path, const Camera& base, const std::string& source) {
  int frame = 0;
  for (int segment = 0; segment < static_cast<int>(path.keyframes.size()); ++segment) {
    const bool last = segment + 1 == static_cast<int>(path.keyframes.size());
    const int frames = last ? 1 : path.keyframes[segment].frames;
    for (int i = 0; i < frames; ++i, ++frame) {
      const std::string problem = pose_problem(pose_in_segment(path, segment, segment_t(path, segment, i), base), base);
      if (!problem.empty()) refuse(source, "frame " + std::to_string(frame) + ": " + problem);
    }
  }
}

Camera camera_on_path(const CameraPath& path, int frame, const Camera& base) {
  const std::vector<CameraKeyframe>& k = path.keyframes;
  int segment = 0, start = 0;
  while (segment + 1 < static_cast<int>(k.size()) - 1 && frame >= start + k[segment].frames) start += k[segment++].frames;
  const PathPose pose = pose_in_segment(path, segment, segment_t(path, segment, frame - start), base);
  return look_at(base, pose.position, pose.target, pose.fov_degrees);
}

}  // namespace pxf
