// app/scene/camera.h: the pose parser and the camera in the scene frame.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include <glm/geometric.hpp>

#include "app/scene/camera.h"

namespace terravol::app::scene {
namespace {

TEST(CameraPose, ParsesFiveNumbers) {
  const CameraPose p = parse_camera_pose("44.25,-71.3,1917.5,90,-12.5");
  EXPECT_DOUBLE_EQ(p.lat, 44.25);
  EXPECT_DOUBLE_EQ(p.lon, -71.3);
  EXPECT_DOUBLE_EQ(p.alt, 1917.5);
  EXPECT_DOUBLE_EQ(p.heading_deg, 90.0);
  EXPECT_DOUBLE_EQ(p.pitch_deg, -12.5);
}

TEST(CameraPose, RejectsMalformedTextWithTheOptionName) {
  for (const char* bad : {"", "1,2,3,4", "1,2,3,4,5,6", "a,2,3,4,5", "1,,3,4,5", "1,2,3,4,5x", "1,2,3,4,nan",
                          "86,0,100,0,0", "0,0,100,0,91"}) {
    try {
      parse_camera_pose(bad);
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("--camera"), std::string::npos) << e.what();
    }
  }
}

TEST(SceneCamera, HeadingIsClockwiseFromNorthAndPitchAboveTheHorizon) {
  const io::SceneFrame frame(45.0, 6.0);
  auto forward = [&](double heading, double pitch) {
    return make_scene_camera(frame, {45.0, 6.0, 1000.0, heading, pitch}, 1000.0, 45.0, 640, 480, 1.0).forward;
  };
  const glm::dvec3 north = forward(0, 0), east = forward(90, 0), down = forward(0, -90), up30 = forward(180, 30);
  EXPECT_NEAR(north.y, 1.0, 1e-12);
  EXPECT_NEAR(east.x, 1.0, 1e-12);
  EXPECT_NEAR(down.z, -1.0, 1e-12);
  EXPECT_NEAR(up30.y, -std::cos(30.0 * 3.14159265358979 / 180.0), 1e-9);
  EXPECT_NEAR(up30.z, 0.5, 1e-9);
}

TEST(SceneCamera, UpIsUnitAndOrthogonalToForward) {
  const io::SceneFrame frame(44.5, -71.5);
  for (double heading : {0.0, 37.0, 200.0})
    for (double pitch : {-90.0, -30.0, 0.0, 45.0}) {
      const auto c = make_scene_camera(frame, {44.9, -71.1, 800.0, heading, pitch}, 800.0, 45.0, 640, 480, 1.0);
      EXPECT_NEAR(glm::length(c.forward), 1.0, 1e-12);
      EXPECT_NEAR(glm::length(c.up), 1.0, 1e-12);
      EXPECT_NEAR(glm::dot(c.forward, c.up), 0.0, 1e-12);
    }
}

TEST(SceneCamera, RollBanksRightAboutTheViewDirection) {
  const io::SceneFrame frame(45.0, 6.0);
  CameraPose pose{45.0, 6.0, 1000.0, 90.0, -20.0};
  const mrbsp::Camera level = make_scene_camera(frame, pose, 1000.0, 45.0, 640, 480, 1.0);
  const glm::dvec3 right = glm::cross(level.forward, level.up);
  pose.roll_deg = 90.0;
  const mrbsp::Camera banked = make_scene_camera(frame, pose, 1000.0, 45.0, 640, 480, 1.0);
  EXPECT_NEAR(glm::distance(banked.forward, level.forward), 0.0, 1e-12) << "roll keeps the view direction";
  EXPECT_NEAR(glm::distance(banked.up, right), 0.0, 1e-12) << "at 90 degrees up is the old right";
  pose.roll_deg = -30.0;
  const mrbsp::Camera left = make_scene_camera(frame, pose, 1000.0, 45.0, 640, 480, 1.0);
  EXPECT_NEAR(glm::dot(left.up, level.up), std::cos(30.0 * 3.14159265358979 / 180.0), 1e-12);
  EXPECT_LT(glm::dot(left.up, right), 0.0) << "negative roll banks left";
  EXPECT_NEAR(glm::length(left.up), 1.0, 1e-12);
}

TEST(SceneCamera, EyeDropsWithTheEarthsCurvatureLikeTheTerrain) {
  const io::SceneFrame frame(44.5, -71.5);
  const auto c = make_scene_camera(frame, {44.9, -71.1, 0, 0, 0}, 1500.0, 45.0, 640, 480, 1.0);
  const io::ScenePoint p = frame.to_scene({44.9, -71.1, 1500.0});
  EXPECT_NEAR(c.eye.x, p.x, 1e-6);
  EXPECT_NEAR(c.eye.y, p.y, 1e-6);
  EXPECT_NEAR(c.eye.z, p.z, 1e-6);
  EXPECT_LT(c.eye.z, 1500.0 - 200.0) << "about 54 km from the origin the drop is about 230 m";
}

TEST(SceneCamera, NearPlaneFollowsTheClearance) {
  EXPECT_DOUBLE_EQ(near_plane_for(100.0), 5.0);
  EXPECT_DOUBLE_EQ(near_plane_for(1.0), 0.5);
  EXPECT_DOUBLE_EQ(near_plane_for(1e6), 200.0);
}

}  // namespace
}  // namespace terravol::app::scene
