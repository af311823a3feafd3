#include "io/geographic.h"

#include <GeographicLib/UTMUPS.hpp>
#include <gtest/gtest.h>

#include "io/error.h"

namespace terravol::io {
namespace {

// A UTM grid whose heights are a linear function of easting and northing: bilinear
// resampling must reproduce it exactly at every geographic sample inside the footprint.
Grid linear_utm_grid(int zone, bool north, double e0, double n0, int rows = 60, int cols = 50) {
  Grid g;
  g.format = "test";
  g.georef = {Crs::kUtm, zone, north, e0, n0, 30.0, 30.0};
  g.allocate(rows, cols);
  for (int r = 0; r < g.rows; ++r)
    for (int c = 0; c < g.cols; ++c) g.heights[g.index(r, c)] = static_cast<float>(0.01 * (c * 30.0) + 0.02 * (r * 30.0));
  return g;
}

void expect_linear_function_survives(int zone, bool north, double e0, double n0) {
  const Grid utm = linear_utm_grid(zone, north, e0, n0);
  const Grid geo = to_geographic(utm, "mem");
  ASSERT_EQ(geo.georef.crs, Crs::kGeographic);
  ASSERT_FALSE(geo.notes.empty());
  std::size_t inside = 0;
  for (int r = 0; r < geo.rows; ++r) {
    for (int c = 0; c < geo.cols; ++c) {
      const std::size_t i = geo.index(r, c);
      if (geo.mask[i] != Sample::kValid) continue;
      double x = 0, y = 0, gamma = 0, k = 0;
      int z = 0;
      bool n = true;
      GeographicLib::UTMUPS::Forward(geo.georef.y0 - r * geo.georef.dy, geo.georef.x0 + c * geo.georef.dx, z, n, x, y,
                                     gamma, k, zone);
      const double cc = (x - e0) / 30.0, rr = (n0 - y) / 30.0;
      if (cc < 0 || cc > utm.cols - 1 || rr < 0 || rr > utm.rows - 1) continue;
      ++inside;
      EXPECT_NEAR(geo.heights[i], 0.01 * (cc * 30.0) + 0.02 * (rr * 30.0), 1e-3);
    }
  }
  EXPECT_GT(inside, static_cast<std::size_t>(0.8 * utm.size()));
}

TEST(ToGeographic, BilinearResamplingReproducesALinearSurfaceNorth) {
  expect_linear_function_survives(10, true, 560000.0, 5120000.0);
}

TEST(ToGeographic, BilinearResamplingReproducesALinearSurfaceSouth) {
  expect_linear_function_survives(25, false, 290000.0, 9115000.0);
}

TEST(ToGeographic, SpacingIsEquivalentToTheProjectedSpacing) {
  const Grid geo = to_geographic(linear_utm_grid(10, true, 560000.0, 5120000.0), "mem");
  // 30 m is about 0.97" of latitude and 1.4" of longitude at 46 N.
  EXPECT_NEAR(geo.georef.dy * 3600.0, 0.97, 0.01);
  EXPECT_NEAR(geo.georef.dx * 3600.0, 1.40, 0.02);
}

TEST(ToGeographic, SamplesOutsideTheFootprintAreMarkedOutside) {
  // 200 km east of the central meridian the grid is rotated by about 1.4 degrees.
  const Grid geo = to_geographic(linear_utm_grid(10, true, 700000.0, 5120000.0, 400, 400), "mem");
  EXPECT_GT(count(geo, Sample::kOutside), 1000u) << "a UTM rectangle is rotated against the meridians";
}

TEST(ToGeographic, RejectsAnInvalidZone) {
  Grid g = linear_utm_grid(10, true, 560000.0, 5120000.0);
  g.georef.utm_zone = 61;
  EXPECT_THROW(to_geographic(g, "mem"), FormatError);
}

}  // namespace
}  // namespace terravol::io
