#include "objects/placement.h"

#include <gtest/gtest.h>

#include <GeographicLib/Geodesic.hpp>

#include <glm/geometric.hpp>

#include <random>

#include "reference/frame.h"

namespace terravol::objects {
namespace {

// A +Y-up box model (glTF axes): x in [-1, 1] (left), y in [0.5, 2.5] (up), z in [-3, 3]
// (front). Its anchor is the bottom centre, (0, 0.5, 0). Vertices: the corners, then the front's
// bottom middle (0, 0.5, 3), the top centre (0, 2.5, 0) and the left side's bottom middle
// (1, 0.5, 0) (glTF's +x is the model's left: its front faces +z with +y up).
volume::Mesh box_model() {
  volume::Mesh m;
  for (int c = 0; c < 8; ++c) m.vertices.emplace_back(c & 1 ? 1.0 : -1.0, c & 2 ? 2.5 : 0.5, c & 4 ? 3.0 : -3.0);
  m.vertices.emplace_back(0.0, 0.5, 3.0);
  m.vertices.emplace_back(0.0, 2.5, 0.0);
  m.vertices.emplace_back(1.0, 0.5, 0.0);
  m.colors.assign(m.vertices.size(), glm::u8vec4(10, 20, 30, 200));
  m.triangles = {0, 1, 3, 0, 3, 2};
  return m;
}
constexpr std::size_t kFront = 8, kTop = 9, kLeft = 10;

// The scene frame's origin a little away from the object, so that the frame's curvature drop
// and scale matter.
const io::SceneFrame kFrame(44.2, -71.4);
const reference::Frame kReference(44.2, -71.4);

// Where the reference puts a point `distance` metres from (lat, lon) along azimuth `azimuth`
// (a geodesic), `up` metres above h.
glm::dvec3 expected(double lat, double lon, double h, double azimuth, double distance, double up) {
  double lat2 = lat, lon2 = lon;
  GeographicLib::Geodesic::WGS84().Direct(lat, lon, azimuth, distance, lat2, lon2);
  return kReference.to_scene(lat2, lon2, h + up);
}

glm::dvec3 at(const volume::Mesh& m, std::size_t k) { return m.vertices[k]; }

TEST(Placement, AnchorOfAYUpModelIsTheBottomCentre) {
  EXPECT_EQ(anchor_of(box_model(), UpAxis::kY), glm::dvec3(0.0, 0.5, 0.0));
  EXPECT_EQ(anchor_of(box_model(), UpAxis::kZ), glm::dvec3(0.0, 1.5, -3.0));
}

TEST(Placement, FrontFacesTheHeadingAndTopIsUp) {
  const volume::Mesh model = box_model();
  Pose pose;
  pose.lat = 44.25;
  pose.lon = -71.33;
  pose.height = 812.5;
  for (const double heading : {0.0, 37.0, 90.0, 200.0}) {
    pose.heading_deg = heading;
    const volume::Mesh m = place(model, anchor_of(model, UpAxis::kY), pose, kFrame);
    EXPECT_LT(glm::length(at(m, kFront) - expected(pose.lat, pose.lon, pose.height, heading, 3.0, 0.0)), 1e-3) << heading;
    EXPECT_LT(glm::length(at(m, kTop) - expected(pose.lat, pose.lon, pose.height, 0.0, 0.0, 2.0)), 1e-6) << heading;
    // The model's left (+x) is 90 degrees anticlockwise of the front.
    EXPECT_LT(glm::length(at(m, kLeft) - expected(pose.lat, pose.lon, pose.height, heading - 90.0, 1.0, 0.0)), 1e-3)
        << heading;
  }
}

TEST(Placement, PitchRaisesTheFrontAndRollLowersTheRight) {
  const volume::Mesh model = box_model();
  Pose pose;
  pose.lat = 44.1;
  pose.lon = -71.5;
  pose.height = 300.0;
  pose.heading_deg = 30.0;
  pose.pitch_deg = 90.0;
  volume::Mesh m = place(model, anchor_of(model, UpAxis::kY), pose, kFrame);
  EXPECT_LT(glm::length(at(m, kFront) - expected(pose.lat, pose.lon, pose.height, 0.0, 0.0, 3.0)), 1e-3);
  pose.pitch_deg = 0.0;
  pose.roll_deg = 90.0;  // right side down: the left side (+x of the model) goes up
  m = place(model, anchor_of(model, UpAxis::kY), pose, kFrame);
  EXPECT_LT(glm::length(at(m, kLeft) - expected(pose.lat, pose.lon, pose.height, 0.0, 0.0, 1.0)), 1e-3);
  EXPECT_LT(glm::length(at(m, kFront) - expected(pose.lat, pose.lon, pose.height, 30.0, 3.0, 0.0)), 1e-3);
}

TEST(Placement, ZUpModelAndScale) {
  const volume::Mesh model = box_model();  // read as +Z up: its +y is the front, +z up
  Pose pose;
  pose.lat = 44.3;
  pose.lon = -71.2;
  pose.height = 100.0;
  pose.heading_deg = 90.0;
  pose.scale = 2.5;
  pose.up = UpAxis::kZ;
  const volume::Mesh m = place(model, anchor_of(model, UpAxis::kZ), pose, kFrame);
  // Vertex 9 (0, 2.5, 0) is 1 in front of the anchor (0, 1.5, -3) and 3 above it.
  EXPECT_LT(glm::length(at(m, kTop) - expected(pose.lat, pose.lon, pose.height, 90.0, 2.5 * 1.0, 2.5 * 3.0)), 1e-3);
}

TEST(Placement, RandomPosesKeepTheModelsShapeTimesItsScale) {
  const volume::Mesh model = box_model();
  std::mt19937 rng(16);
  std::uniform_real_distribution<double> angle(-180.0, 180.0), scale(0.1, 20.0);
  for (int run = 0; run < 200; ++run) {
    Pose pose;
    // Near the frame's origin at the datum, where the frame keeps lengths: away from it the
    // curvature drop shears what stands there by (distance from the origin) / R, as it does the
    // terrain under it, and at height h horizontal lengths shrink by h / R.
    pose.lat = 44.2;
    pose.lon = -71.4 + angle(rng) / 180000.0;  // within 0.001 degrees, 80 m
    pose.height = 0.0;
    pose.heading_deg = angle(rng);
    pose.pitch_deg = angle(rng) / 2.0;
    pose.roll_deg = angle(rng);
    pose.scale = scale(rng);
    const volume::Mesh m = place(model, anchor_of(model, UpAxis::kY), pose, kFrame);
    for (std::size_t i = 0; i < model.vertices.size(); ++i) {
      for (std::size_t j = i + 1; j < model.vertices.size(); ++j) {
        const double want = pose.scale * glm::length(model.vertices[i] - model.vertices[j]);
        EXPECT_NEAR(glm::length(m.vertices[i] - m.vertices[j]), want, 3e-5 * want + 1e-6) << run << " " << i << " " << j;
      }
    }
  }
}

TEST(Placement, OpacityScalesAlphaAndBadPosesThrow) {
  const volume::Mesh model = box_model();
  Pose pose;
  pose.lat = 44.2;
  pose.lon = -71.4;
  const volume::Mesh m = place(model, anchor_of(model, UpAxis::kY), pose, kFrame, 0.5);
  EXPECT_EQ(m.colors[0], glm::u8vec4(10, 20, 30, 100));
  pose.scale = 0.0;
  EXPECT_THROW(place(model, glm::dvec3(0.0), pose, kFrame), std::invalid_argument);
  pose.scale = 1.0;
  EXPECT_THROW(place(model, glm::dvec3(0.0), pose, kFrame, 1.5), std::invalid_argument);
}

}  // namespace
}  // namespace terravol::objects
