#include "io/scene_frame.h"

#include <GeographicLib/Geodesic.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace terravol::io {
namespace {

TEST(SceneFrame, MeridiansAndParallelsAreExactPlanes) {
  const SceneFrame f(44.5, -71.5);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> lat(43.0, 46.0), lon(-73.0, -70.0), h(-100.0, 5000.0);
  for (int i = 0; i < 1000; ++i) {
    const double lo = lon(rng), la = lat(rng);
    // Same longitude at any latitude and height: the same x, bit for bit.
    EXPECT_EQ(f.to_scene({lat(rng), lo, h(rng)}).x, f.to_scene({lat(rng), lo, h(rng)}).x);
    EXPECT_EQ(f.to_scene({la, lon(rng), h(rng)}).y, f.to_scene({la, lon(rng), h(rng)}).y);
  }
}

TEST(SceneFrame, ToGeodeticInvertsToScene) {
  const SceneFrame f(-45.5, -65.5);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> lat(-47.0, -44.0), lon(-67.0, -64.0), h(-100.0, 9000.0);
  for (int i = 0; i < 1000; ++i) {
    const Geodetic g{lat(rng), lon(rng), h(rng)};
    const Geodetic back = f.to_geodetic(f.to_scene(g));
    EXPECT_NEAR(back.lat, g.lat, 1e-12);
    EXPECT_NEAR(back.lon, g.lon, 1e-12);
    EXPECT_NEAR(back.h, g.h, 1e-8);
  }
}

TEST(SceneFrame, CurvatureDropLowersDistantPoints) {
  const SceneFrame f(40.0, -111.0);
  EXPECT_EQ(f.to_scene({40.0, -111.0, 100.0}).z, 100.0);
  // 100 km away the drop is about d^2 / 2R, roughly 785 m.
  const ScenePoint p = f.to_scene({40.0 + 100000.0 / f.metres_per_degree_lat(), -111.0, 0.0});
  EXPECT_NEAR(p.z, -(1e5 * 1e5) / (2 * f.curvature_radius()), 1e-6);
  EXPECT_NEAR(p.z, -785.0, 5.0);
}

TEST(SceneFrame, SpansTheAntimeridian) {
  const SceneFrame f(-17.0, 179.5);
  EXPECT_NEAR(f.x_of_lon(-179.5), f.metres_per_degree_lon(), 1e-6);
  EXPECT_NEAR(f.lon_of_x(f.x_of_lon(-179.5)), -179.5, 1e-12);
}

TEST(SceneFrame, RejectsPolarOrigins) {
  EXPECT_THROW(SceneFrame(89.0, 0.0), std::invalid_argument);
  EXPECT_THROW(SceneFrame(std::nan(""), 0.0), std::invalid_argument);
}

// The frame's scale against true ellipsoidal distances (GeographicLib geodesics): exact at the
// origin, and the documented error at the edge of a 2-degree window at 45 degrees.
TEST(SceneFrame, ScaleErrorMatchesGeodesicsAndItsDocumentedBound) {
  const auto& geod = GeographicLib::Geodesic::WGS84();
  const SceneFrame f(45.0, 7.0);
  auto frame_vs_geodesic = [&](double lat, double lon, double dlat, double dlon) {
    double s12 = 0;
    geod.Inverse(lat, lon, lat + dlat, lon + dlon, s12);
    const ScenePoint a = f.to_scene({lat, lon, 0}), b = f.to_scene({lat + dlat, lon + dlon, 0});
    return std::hypot(b.x - a.x, b.y - a.y) / s12 - 1.0;
  };
  EXPECT_NEAR(frame_vs_geodesic(45.0, 7.0, 0.0, 0.001), 0.0, 1e-6);
  EXPECT_NEAR(frame_vs_geodesic(45.0, 7.0, 0.001, 0.0), 0.0, 1e-6);
  const double east_at_edge = frame_vs_geodesic(46.0, 7.0, 0.0, 0.001);
  EXPECT_NEAR(east_at_edge, f.scale_error(46.0), 1e-4);
  EXPECT_GT(f.scale_error(46.0), 0.015);
  EXPECT_LT(f.scale_error(46.0), 0.02);
  EXPECT_LT(f.scale_error(45.5), 0.01);
  EXPECT_EQ(f.scale_error(45.0), 0.0);
}

}  // namespace
}  // namespace terravol::io
