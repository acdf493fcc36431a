// Camera paths (app/camera_path.h): parsing, refusals with one-line errors, interpolation.
#include <gtest/gtest.h>

#include <cmath>

#include "app/camera_path.h"
#include "core/error.h"

namespace pxf {
namespace {

const char* kTwoKeys = R"({"interpolation": "linear", "keyframes": [
  {"position": [0, 1, 4], "target": [0, 1, 0], "fov": 40, "frames": 4},
  {"position": [4, 1, 0], "target": [0, 1, 0], "fov": 60}]})";

glm::vec3 eye(const Camera& c) { return glm::vec3(c.camera_to_world[3]); }
glm::vec3 forward(const Camera& c) { return -glm::vec3(c.camera_to_world[2]); }

TEST(CameraPath, ParsesKeyframesAndInterpolatesLinearly) {
  const CameraPath path = parse_camera_path(kTwoKeys, "test.json");
  ASSERT_EQ(path.keyframes.size(), 2u);
  EXPECT_FALSE(path.spline);
  EXPECT_EQ(path.frame_count(), 5);
  const Camera base;
  const Camera first = camera_on_path(path, 0, base), middle = camera_on_path(path, 2, base), last = camera_on_path(path, 4, base);
  EXPECT_NEAR(glm::length(eye(first) - glm::vec3(0, 1, 4)), 0.0f, 1e-5f);
  EXPECT_NEAR(glm::length(eye(middle) - glm::vec3(2, 1, 2)), 0.0f, 1e-5f);
  EXPECT_NEAR(glm::length(eye(last) - glm::vec3(4, 1, 0)), 0.0f, 1e-5f);
  EXPECT_NEAR(glm::degrees(middle.yfov), 50.0f, 1e-4f);
  // Looking at the target.
  EXPECT_NEAR(glm::dot(forward(middle), glm::normalize(glm::vec3(0, 1, 0) - eye(middle))), 1.0f, 1e-5f);
}

TEST(CameraPath, TheSplinePassesThroughEveryKeyframe) {
  const CameraPath path = parse_camera_path(R"({"interpolation": "spline", "keyframes": [
    {"position": [0, 0, 4], "target": [0, 0, 0], "frames": 3},
    {"position": [4, 0, 0], "target": [0, 0, 0], "frames": 3},
    {"position": [0, 0, -4], "target": [0, 0, 0]}]})", "s.json");
  EXPECT_TRUE(path.spline);
  const Camera base;
  EXPECT_NEAR(glm::length(eye(camera_on_path(path, 3, base)) - glm::vec3(4, 0, 0)), 0.0f, 1e-5f);
  EXPECT_NEAR(glm::length(eye(camera_on_path(path, 6, base)) - glm::vec3(0, 0, -4)), 0.0f, 1e-5f);
  // Between keyframes the spline bulges outwards, where a linear path cuts the corner.
  const glm::vec3 p = eye(camera_on_path(path, 1, base));
  EXPECT_GT(glm::length(p), glm::length(glm::mix(glm::vec3(0, 0, 4), glm::vec3(4, 0, 0), 1.0f / 3.0f)));
  EXPECT_FLOAT_EQ(camera_on_path(path, 1, base).yfov, base.yfov);  // no fov: the base camera's
}

void expect_refused(const std::string& text, const std::string& expected) {
  try {
    parse_camera_path(text, "bad.json");
    ADD_FAILURE() << "accepted: " << text;
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    EXPECT_NE(message.find("camera path bad.json: "), std::string::npos) << message;
    EXPECT_NE(message.find(expected), std::string::npos) << message;
  }
}

TEST(CameraPath, MalformedFilesAreRefusedWithOneLine) {
  expect_refused("{", "not valid JSON");
  expect_refused("[]", "top level");
  expect_refused(R"({"keyframes": 3})", "no \"keyframes\"");
  expect_refused(R"({"keyframes": [{"position": [0,0,1], "target": [0,0,0]}]})", "at least two");
  expect_refused(R"({"interpolation": "cubic", "keyframes": []})", "\"interpolation\"");
  expect_refused(R"({"keyframes": [{"position": [0,0,1], "target": [0,0,0]}, {"position": [1,0,1], "target": [0,0,0]}]})",
                 "keyframe 1: no \"frames\"");
  expect_refused(R"({"keyframes": [{"position": [0,0], "target": [0,0,0], "frames": 2}, {"position": [1,0,1], "target": [0,0,0]}]})",
                 "\"position\" must be an array of 3");
  expect_refused(R"({"keyframes": [{"position": [0,0,1], "target": [0,0,0], "frames": 2}, {"position": [1,"a",1], "target": [0,0,0]}]})",
                 "keyframe 2: \"position\"");
  expect_refused(R"({"keyframes": [{"position": [0,0,0], "target": [0,0,0], "frames": 2}, {"position": [1,0,1], "target": [0,0,0]}]})",
                 "coincide");
  expect_refused(R"({"keyframes": [{"position": [0,0,1], "target": [0,0,0], "fov": 180, "frames": 2}, {"position": [1,0,1], "target": [0,0,0]}]})",
                 "\"fov\"");
  expect_refused(R"({"keyframes": [{"position": [0,0,1], "target": [0,0,0], "frames": 0}, {"position": [1,0,1], "target": [0,0,0]}]})",
                 "\"frames\" must be an integer");
  expect_refused(R"({"keyframes": [{"position": [0,0,1], "target": [0,0,0], "frames": 2.5}, {"position": [1,0,1], "target": [0,0,0]}]})",
                 "\"frames\" must be an integer");
  expect_refused(R"({"keyframes": [{"position": [0,0,1], "target": [0,0,0], "frames": 60000}, {"position": [1,0,1], "target": [0,0,0], "frames": 60000}, {"position": [2,0,1], "target": [0,0,0]}]})",
                 "more than");
}

TEST(CameraPath, PositionsBeyondTheBoundAreRefusedInDoublesAndAfterNarrowing) {
  expect_refused(R"({"keyframes": [{"position": [1e300,0,1], "target": [0,0,0], "frames": 2}, {"position": [1,0,1], "target": [0,0,0]}]})",
                 "within +-1e12");
  expect_refused(R"({"keyframes": [{"position": [1e20,0,1], "target": [0,0,0], "frames": 2}, {"position": [1,0,1], "target": [0,0,0]}]})",
                 "within +-1e12");
  expect_refused(R"({"keyframes": [{"position": [0,0,1], "target": [0,0,-2e12], "frames": 2}, {"position": [1,0,1], "target": [0,0,0]}]})",
                 "within +-1e12");
}

// Keyframes that are fine alone can still give a bad camera between them: position and target
// that cross in the middle of a segment, a spline that overshoots the bound.
TEST(CameraPath, EveryFramesCameraIsChecked) {
  const Camera base;
  const CameraPath crossing = parse_camera_path(R"({"keyframes": [
    {"position": [0,0,1], "target": [0,0,-1], "frames": 2},
    {"position": [0,0,-1], "target": [0,0,1]}]})", "cross.json");
  try {
    check_path_cameras(crossing, base, "cross.json");
    FAIL() << "position and target meet at frame 1";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("camera path cross.json: frame 1: position and target meet"), std::string::npos)
        << e.what();
  }
  const CameraPath overshoot = parse_camera_path(R"({"interpolation": "spline", "keyframes": [
    {"position": [0,0,1], "target": [0,0,0], "frames": 25},
    {"position": [9.9e11,0,1], "target": [0,0,0], "frames": 25},
    {"position": [-9.9e11,0,1], "target": [0,0,0]}]})", "overshoot.json");  // 1.009e12 near frame 23
  EXPECT_THROW(check_path_cameras(overshoot, base, "overshoot.json"), Error);
  const CameraPath fine = parse_camera_path(kTwoKeys, "fine.json");
  EXPECT_NO_THROW(check_path_cameras(fine, base, "fine.json"));
}

TEST(CameraPath, AnUnreadableFileIsRefusedWithOneLine) {
  EXPECT_THROW(read_camera_path("/nonexistent/path.json"), Error);
}

}  // namespace
}  // namespace pxf
