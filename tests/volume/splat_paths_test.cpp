// SPLAT!'s profiles of an area map (volume/splat_paths.h) on a synthetic SDF-like tile. The
// check against SPLAT! itself (every point it wrote reproduced at its position) is in
// splat_cli_test.cpp (splat-volume --check-itm).
#include "volume/splat_paths.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <stdexcept>
#include <vector>

#include "volume/itm.h"

namespace terravol::volume {
namespace {

// One tile 40..41 N, 112..111 W at SPLAT!'s 1200 cells per degree, row 0 north, heights
// integer metres from a seeded hash.
io::Grid tile() {
  io::Grid g;
  g.georef.crs = io::Crs::kGeographic;
  g.georef.dx = g.georef.dy = 1.0 / 1200.0;
  g.georef.x0 = -112.0;
  g.georef.y0 = 40.0 + 1199.0 / 1200.0;
  g.allocate(1200, 1200);
  unsigned s = 12345u;
  for (float& h : g.heights) {
    s = s * 1664525u + 1013904223u;
    h = static_cast<float>(1300 + (s >> 24));
  }
  return g;
}

AnoMap bounds() {
  AnoMap m;
  m.max_west = 112, m.min_west = 111, m.max_north = 41, m.min_north = 40;
  return m;
}

// Great circle on SPLAT!'s sphere (3959 miles), metres.
double sphere_m(double lat1, double lon1, double lat2, double lon2) {
  const double d = M_PI / 180.0;
  return 3959.0 * 1609.344 *
         std::acos(std::sin(lat1 * d) * std::sin(lat2 * d) + std::cos(lat1 * d) * std::cos(lat2 * d) * std::cos((lon1 - lon2) * d));
}

TEST(SplatPaths, EachCellOnceWithinTheRangeNearlyAllOfTheDisc) {
  const io::Grid g = tile();
  const double tx_lat = 40.5, tx_lon = -111.5, radius_km = 4.0;
  std::set<std::pair<long, long>> cells;
  std::size_t points = 0;
  const double tx_ground = 3.28084 * 0.3048 * g.heights[g.index(599, 600)];
  for_each_splat_point(g, bounds(), tx_lat, tx_lon, radius_km, 1200, [&](const SplatPathPoint& p) {
    ++points;
    const long r = std::lround((g.georef.y0 - p.lat) * 1200.0), c = std::lround((p.lon - g.georef.x0) * 1200.0);
    EXPECT_TRUE(cells.insert({r, c}).second) << "cell " << r << ", " << c << " twice";
    ASSERT_GE(p.ground_m.size(), 2u);
    EXPECT_DOUBLE_EQ(p.ground_m[0], tx_ground);
    // The point is the sample after the profile's last: as many steps out as the profile has samples.
    const double d = sphere_m(tx_lat, tx_lon, p.lat, p.lon);
    EXPECT_NEAR(d, p.spacing_m * static_cast<double>(p.ground_m.size()), 1e-6 * d + 1e-3);
    EXPECT_LE(d, radius_km * 1000.0 + 1e-6);
    EXPECT_GT(p.spacing_m, 60.0);  // between a cell's east-west (70 m) and diagonal sizes
    EXPECT_LT(p.spacing_m, 100.0);
  });
  // Every cell whose centre lies more than two cells out and two cells inside the range, but
  // for the rare one between radials.
  std::size_t inside = 0, missed = 0;
  for (long r = 0; r < g.rows; ++r)
    for (long c = 0; c < g.cols; ++c) {
      const double lat = g.georef.y0 - r / 1200.0, lon = g.georef.x0 + c / 1200.0;
      const double d = sphere_m(tx_lat, tx_lon, lat, lon);
      if (d < 250.0 || d > radius_km * 1000.0 - 250.0) continue;
      ++inside;
      if (!cells.count({r, c})) ++missed;
    }
  EXPECT_GT(inside, 5000u);
  EXPECT_LT(missed, inside / 500) << missed << " of " << inside;
  EXPECT_EQ(points, cells.size());
}

TEST(SplatPaths, TransmitterOutsideTheRegionIsAnError) {
  const io::Grid g = tile();
  EXPECT_THROW(for_each_splat_point(g, bounds(), 42.0, -111.5, 4.0, 1200, [](const SplatPathPoint&) {}),
               std::invalid_argument);
  EXPECT_THROW(for_each_splat_point(g, bounds(), 40.5, -111.5, 4.0, 900, [](const SplatPathPoint&) {}),
               std::invalid_argument);
}

// A map written from the profiles with the ITM computed here (itm_point_to_point) plus 0.25
// dB: every point found, the difference found; one point moved by 1e-5 degree is not.
TEST(SplatPaths, CheckMatchesPointsByPositionAndMeasuresTheDifference) {
  const io::Grid g = tile();
  AnoMap map = bounds();
  const double tx_lat = 40.5, tx_lon = -111.5, radius_km = 2.0;
  const SplatSite site{"tx", tx_lat, tx_lon, 30.0};
  const SplatLrp lrp;
  ItmParameters p;
  for_each_splat_point(g, map, tx_lat, tx_lon, radius_km, 1200, [&](const SplatPathPoint& q) {
    AnoPoint a;
    a.lat = q.lat;
    a.lon = q.lon;
    a.value = static_cast<float>(itm_point_to_point(q.ground_m, q.spacing_m, 30.0, 10.0, 900.0, p).loss_db + 0.25);
    map.points.push_back(a);
  });
  ASSERT_GT(map.points.size(), 1500u);
  map.points[100].lat += 1e-5;
  const SplatItmCheck c = check_itm_on_splat_profiles(g, map, site, lrp, 10.0, radius_km);
  EXPECT_EQ(c.reported, map.points.size());
  EXPECT_EQ(c.reproduced, map.points.size() - 1);
  EXPECT_EQ(c.unmatched, 1u);
  EXPECT_NEAR(c.comparison.median_difference, 0.25, 1e-4);  // float rounding of the values
  EXPECT_NEAR(c.max_abs_difference, 0.25, 1e-4);
  EXPECT_GT(c.comparison.pearson, 0.99999);
}

}  // namespace
}  // namespace terravol::volume
