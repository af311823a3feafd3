// Picking (app/scene/pick.h) against geometry worked out by hand: the pixel rays of a camera,
// a ray down onto flat ground and one slanting onto it, a triangle in front of the ground and
// one behind it, and the sky.
#include "app/scene/pick.h"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace terravol::app::scene {
namespace {

constexpr double kLat0 = 45.5, kLon0 = 6.5;

bool anywhere(double, double) { return true; }
double flat(double, double) { return 100.0; }

TEST(PixelRay, CentreIsTheViewAndTheTopRowIsHalfTheFieldAbove) {
  mrbsp::Camera c;
  c.eye = {10.0, 20.0, 30.0};
  c.forward = {0.0, 1.0, 0.0};
  c.up = {0.0, 0.0, 1.0};
  c.fov_y_deg = 60.0;
  c.width = 400;
  c.height = 200;
  const Ray centre = pixel_ray(c, 199.5, 99.5);
  EXPECT_EQ(centre.origin, c.eye);
  EXPECT_NEAR(centre.direction.y, 1.0, 1e-12);
  // The view's top edge is 30 degrees up and its right edge atan(2 tan 30) to the right
  // (aspect 2); the centres of the top row and the right column lie half a pixel inside.
  const Ray top = pixel_ray(c, 199.5, 199.0);
  const double up_deg = std::atan2(top.direction.z, top.direction.y) * 180.0 / std::numbers::pi;
  EXPECT_NEAR(up_deg, std::atan(std::tan(std::numbers::pi / 6.0) * 199.0 / 200.0) * 180.0 / std::numbers::pi, 1e-9);
  const Ray right = pixel_ray(c, 399.0, 99.5);
  EXPECT_NEAR(right.direction.x / right.direction.y, 2.0 * std::tan(std::numbers::pi / 6.0) * 399.0 / 400.0, 1e-9);
  EXPECT_NEAR(glm::length(right.direction), 1.0, 1e-12);
}

TEST(Pick, StraightDownHitsFlatGroundUnderTheEye) {
  const io::SceneFrame frame(kLat0, kLon0);
  const io::ScenePoint eye = frame.to_scene({kLat0 + 0.01, kLon0 + 0.01, 1100.0});
  const io::ScenePoint below = frame.to_scene({kLat0 + 0.01, kLon0 + 0.01, 0.0});
  Ray r;
  r.origin = {eye.x, eye.y, eye.z};
  r.direction = glm::normalize(glm::dvec3(below.x, below.y, below.z) - r.origin);
  const auto p = pick(r, frame, flat, anywhere, {}, 50000.0);
  ASSERT_TRUE(p.has_value());
  EXPECT_FALSE(p->on_surface);
  EXPECT_NEAR(p->where.h, 100.0, 2e-3);
  EXPECT_NEAR(p->where.lat, kLat0 + 0.01, 1e-7);
  EXPECT_NEAR(p->where.lon, kLon0 + 0.01, 1e-7);
  EXPECT_NEAR(p->distance, 1000.0, 0.01);
}

// 45 degrees down from 1000 m above flat ground: the hit is 1000 m away horizontally (the
// Earth's curvature over 1 km, 0.08 m, within the tolerance).
TEST(Pick, SlantingRayHitsTheGroundWhereTheAngleSays) {
  const io::SceneFrame frame(kLat0, kLon0);
  const io::ScenePoint eye = frame.to_scene({kLat0, kLon0, 1100.0});
  Ray r;
  r.origin = {eye.x, eye.y, eye.z};
  r.direction = glm::normalize(glm::dvec3(0.0, 1.0, -1.0));  // north, 45 degrees down
  const auto p = pick(r, frame, flat, anywhere, {}, 50000.0);
  ASSERT_TRUE(p.has_value());
  EXPECT_NEAR(p->where.h, 100.0, 2e-3);
  EXPECT_NEAR(p->distance, 1000.0 * std::sqrt(2.0), 0.3);
  EXPECT_NEAR((p->where.lat - kLat0) * 111132.0, 1000.0, 5.0);  // metres per degree at 45.5 N
}

TEST(Pick, NearestOfTerrainAndTrianglesAndNothingInTheSky) {
  const io::SceneFrame frame(kLat0, kLon0);
  const io::ScenePoint eye = frame.to_scene({kLat0, kLon0, 1100.0});
  Ray r;
  r.origin = {eye.x, eye.y, eye.z};
  r.direction = {0.0, 0.0, -1.0};
  // A horizontal triangle 500 m below the eye around its nadir, and one 1050 m below (under
  // the ground, 1000 m below).
  volume::Mesh m;
  for (double dz : {-500.0, -1050.0}) {
    const glm::dvec3 o = r.origin + glm::dvec3(0.0, 0.0, dz);
    m.vertices.push_back(o + glm::dvec3(-50.0, -50.0, 0.0));
    m.vertices.push_back(o + glm::dvec3(50.0, -50.0, 0.0));
    m.vertices.push_back(o + glm::dvec3(0.0, 80.0, 0.0));
  }
  m.triangles = {0, 1, 2};
  auto p = pick(r, frame, flat, anywhere, m, 50000.0);
  ASSERT_TRUE(p.has_value());
  EXPECT_TRUE(p->on_surface);
  EXPECT_NEAR(p->distance, 500.0, 1e-9);
  m.triangles = {3, 4, 5};
  p = pick(r, frame, flat, anywhere, m, 50000.0);
  ASSERT_TRUE(p.has_value());
  EXPECT_FALSE(p->on_surface) << "the ground is in front of the second triangle";
  r.direction = {0.0, 0.6, 0.8};
  EXPECT_FALSE(pick(r, frame, flat, anywhere, m, 50000.0).has_value());
  // Ground outside the window is not hit.
  r.direction = {0.0, 0.0, -1.0};
  EXPECT_FALSE(pick(r, frame, flat, [](double, double) { return false; }, {}, 50000.0).has_value());
}

}  // namespace
}  // namespace terravol::app::scene
