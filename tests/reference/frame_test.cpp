// The reference's scene frame, written from the definition: checked against GeographicLib's own
// measures of the ellipsoid and against io::SceneFrame, a separate implementation of the same
// definition (the renderer's).
#include <GeographicLib/Ellipsoid.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "io/scene_frame.h"
#include "reference/frame.h"

namespace terravol::reference {
namespace {

constexpr double kRad = std::numbers::pi / 180.0;

TEST(Frame, OriginMapsToZeroWithItsHeight) {
  const Frame f(44.5, -71.5);
  const glm::dvec3 p = f.to_scene(44.5, -71.5, 812.5);
  EXPECT_EQ(p.x, 0.0);
  EXPECT_EQ(p.y, 0.0);
  EXPECT_EQ(p.z, 812.5);
}

TEST(Frame, AlongTheOriginParallelXIsTheParallelArc) {
  // GeographicLib's radius of the parallel (a different formula from N cos(lat)).
  const double lat0 = 45.25;
  const Frame f(lat0, 6.0);
  const double r = GeographicLib::Ellipsoid::WGS84().CircleRadius(lat0);
  for (double dlon : {-0.7, -0.01, 0.2, 1.0}) {
    EXPECT_NEAR(f.to_scene(lat0, 6.0 + dlon, 0).x, r * dlon * kRad, 1e-6) << dlon;
  }
}

TEST(Frame, NearTheOriginYIsTheMeridianArc) {
  const double lat0 = 40.7;
  const Frame f(lat0, -111.9);
  const auto& e = GeographicLib::Ellipsoid::WGS84();
  for (double dlat : {-1e-3, 2e-4, 1e-3}) {
    const double arc = e.MeridianDistance(lat0 + dlat) - e.MeridianDistance(lat0);
    EXPECT_NEAR(f.to_scene(lat0 + dlat, -111.9, 0).y, arc, 1e-4) << dlat;  // second order: ~1e-5 m
  }
}

TEST(Frame, CurvatureDropIsTheParabolaOfTheMeanRadius) {
  const Frame f(30.0, 10.0);
  const auto& e = GeographicLib::Ellipsoid::WGS84();
  const double r = std::sqrt(e.MeridionalCurvatureRadius(30.0) * e.TransverseCurvatureRadius(30.0));
  const glm::dvec3 p = f.to_scene(30.3, 10.4, 100.0);
  EXPECT_NEAR(p.z, 100.0 - (p.x * p.x + p.y * p.y) / (2.0 * r), 1e-9);
  EXPECT_GT(100.0 - p.z, 150.0);  // about 51 km from the origin: about 200 m of drop
  EXPECT_LT(100.0 - p.z, 260.0);
}

TEST(Frame, LongitudeDifferencesWrapAcrossTheAntimeridian) {
  const Frame f(-17.0, 179.9);
  // -179.9 is 0.2 degree east of the origin, 179.7 0.2 degree west.
  const glm::dvec3 east = f.to_scene(-17.0, -179.9, 0), west = f.to_scene(-17.0, 179.7, 0);
  EXPECT_GT(east.x, 0.0);
  EXPECT_NEAR(east.x, -west.x, 1e-6);
}

TEST(Frame, AgreesWithTheRenderersOwnFrameAtRandomPoints) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> lat0d(-60, 60), lon0d(-180, 180), off(-1.0, 1.0), h(-100, 4000);
  for (int n = 0; n < 2000; ++n) {
    const double lat0 = lat0d(rng), lon0 = lon0d(rng);
    const Frame mine(lat0, lon0);
    const io::SceneFrame theirs(lat0, lon0);
    const double lat = lat0 + off(rng), lon = lon0 + off(rng), height = h(rng);
    const glm::dvec3 a = mine.to_scene(lat, lon, height);
    const io::ScenePoint b = theirs.to_scene({lat, std::remainder(lon, 360.0), height});
    ASSERT_NEAR(a.x, b.x, 1e-6) << lat0 << " " << lon0 << " " << lat << " " << lon;
    ASSERT_NEAR(a.y, b.y, 1e-6);
    ASSERT_NEAR(a.z, b.z, 1e-6);
  }
}

TEST(Frame, LatitudeAndLongitudeOfXAndYInvertTheMap) {
  const Frame f(44.2, -71.4);
  for (double lat : {43.5, 44.2, 44.9})
    for (double lon : {-72.0, -71.4, -70.8}) {
      const glm::dvec3 p = f.to_scene(lat, lon, 500.0);
      EXPECT_NEAR(f.lat_of(p.y), lat, 1e-12);
      EXPECT_NEAR(f.lon_of(p.x), lon, 1e-12);
    }
}

TEST(Frame, RejectsPolarOrNonFiniteOrigins) {
  EXPECT_THROW(Frame(86.0, 0.0), std::invalid_argument);
  EXPECT_THROW(Frame(-89.0, 0.0), std::invalid_argument);
  EXPECT_THROW(Frame(std::nan(""), 0.0), std::invalid_argument);
}

}  // namespace
}  // namespace terravol::reference
