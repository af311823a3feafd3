#include "volume/surface_raster.h"

#include <GeographicLib/LocalCartesian.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "volume_test_util.h"

namespace terravol::volume {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

VolumeFrame geographic(HeightRef h) {
  VolumeFrame f;
  f.kind = FrameKind::kGeographic;
  f.height = h;
  return f;
}

// Trilinear interpolation written out from the definition, for the tests: the lattice cell
// containing world point w, the eight corner values weighted by the products of the
// fractional distances (within 1e-9 of a spacing of a lattice plane: on it). NaN outside the
// lattice or next to a NaN.
double expected_value(const Volume& v, double w0, double w1, double w2) {
  const double w[3] = {w0, w1, w2};
  int lo[3];
  double f[3];
  for (int a = 0; a < 3; ++a) {
    double x = (w[a] - v.lattice.origin[a]) / v.lattice.spacing[a];
    if (std::abs(x - std::round(x)) < 1e-9) x = std::round(x);  // on a lattice plane, up to rounding
    const int n = v.lattice.dims[a];
    if (x < -1e-9 || x > n - 1 + 1e-9) return kNaN;
    if (n == 1) {
      lo[a] = 0;
      f[a] = 0;
      continue;
    }
    lo[a] = std::min(static_cast<int>(std::floor(std::max(x, 0.0))), n - 2);
    f[a] = std::clamp(x - lo[a], 0.0, 1.0);
  }
  double sum = 0;
  for (int dk = 0; dk < 2; ++dk)
    for (int dj = 0; dj < 2; ++dj)
      for (int di = 0; di < 2; ++di) {
        const double weight = (di ? f[0] : 1 - f[0]) * (dj ? f[1] : 1 - f[1]) * (dk ? f[2] : 1 - f[2]);
        if (weight == 0) continue;
        const double x = v.at(lo[0] + di, lo[1] + dj, lo[2] + dk);
        if (std::isnan(x)) return kNaN;
        sum += weight * x;
      }
  return sum;
}

// A ground that is a plane in latitude and longitude, metres.
double plane_ground(double lat, double lon) { return 1500.0 + 800.0 * (lat - 45.125) - 300.0 * (lon - 6.25); }

void expect_matches(const io::GeoRaster& r, double expected, int row, int col) {
  const float got = r.at(row, col);
  if (std::isnan(expected)) {
    EXPECT_TRUE(std::isnan(got)) << row << "," << col << ": " << got;
  } else {
    EXPECT_NEAR(got, expected, 1e-4) << row << "," << col;
  }
}

TEST(FootprintRaster, GeographicLatticeGivesOnePixelCentredOnEachColumn) {
  const Volume v = test::random_volume(1, {7, 5, 3}, geographic(HeightRef::kGround));
  const io::GeoRaster r = footprint_raster(v);
  EXPECT_EQ(r.rows, 5);
  EXPECT_EQ(r.cols, 7);
  EXPECT_DOUBLE_EQ(r.dlon, v.lattice.spacing[0]);
  EXPECT_DOUBLE_EQ(r.dlat, v.lattice.spacing[1]);
  for (int c = 0; c < r.cols; ++c) EXPECT_NEAR(r.centre_lon(c), v.lattice.world(0, c), 1e-12);
  for (int row = 0; row < r.rows; ++row) EXPECT_NEAR(r.centre_lat(row), v.lattice.world(1, 4 - row), 1e-12);
  EXPECT_NEAR(r.west, v.lattice.origin[0] - v.lattice.spacing[0] / 2, 1e-12);
  EXPECT_NEAR(r.south(), v.lattice.origin[1] - v.lattice.spacing[1] / 2, 1e-12);
}

TEST(SampleSurface, TerrainFollowingVolumeAtAHeightAboveGroundInterpolatesBetweenLayers) {
  Volume v = test::random_volume(2, {6, 4, 5}, geographic(HeightRef::kGround));
  v.values[v.lattice.index(2, 1, 3)] = std::numeric_limits<float>::quiet_NaN();
  io::GeoRaster r = footprint_raster(v);
  for (const double agl : {-37.5, -30.0, 0.0, 1.0, 7.25, 12.5}) {
    EXPECT_GT(sample_surface(v, {HeightRef::kGround, agl}, {}, r), 0u);
    for (int row = 0; row < r.rows; ++row)
      for (int c = 0; c < r.cols; ++c)
        expect_matches(r, expected_value(v, r.centre_lon(c), r.centre_lat(row), agl), row, c);
  }
  EXPECT_EQ(sample_surface(v, {HeightRef::kGround, 500.0}, {}, r), 0u) << "above the top layer";
  EXPECT_TRUE(std::isnan(r.at(0, 0)));
}

TEST(SampleSurface, HeightsAboveTheDatumOfATerrainFollowingVolumeSubtractTheGround) {
  Volume v = test::random_volume(3, {6, 4, 8}, geographic(HeightRef::kGround));
  v.lattice.origin[2] = 0.0;
  v.lattice.spacing[2] = 100.0;  // 0 .. 700 m above ground, over ground of about 1500 m
  io::GeoRaster r = footprint_raster(v);
  EXPECT_THROW(sample_surface(v, {HeightRef::kDatum, 1900.0}, {}, r), std::invalid_argument);
  EXPECT_GT(sample_surface(v, {HeightRef::kDatum, 1900.0}, plane_ground, r), 0u);
  for (int row = 0; row < r.rows; ++row)
    for (int c = 0; c < r.cols; ++c) {
      const double lat = r.centre_lat(row), lon = r.centre_lon(c);
      expect_matches(r, expected_value(v, lon, lat, 1900.0 - plane_ground(lat, lon)), row, c);
    }
}

TEST(SampleSurface, HeightsAboveGroundInADatumVolumeAddTheGround) {
  Volume v = test::random_volume(4, {5, 5, 10}, geographic(HeightRef::kDatum));
  v.lattice.origin[2] = 1400.0;
  v.lattice.spacing[2] = 50.0;
  io::GeoRaster r = footprint_raster(v);
  EXPECT_GT(sample_surface(v, {HeightRef::kGround, 30.0}, plane_ground, r), 0u);
  for (int row = 0; row < r.rows; ++row)
    for (int c = 0; c < r.cols; ++c) {
      const double lat = r.centre_lat(row), lon = r.centre_lon(c);
      expect_matches(r, expected_value(v, lon, lat, 30.0 + plane_ground(lat, lon)), row, c);
    }
}

TEST(SampleSurface, EnuVolumeIsSampledWhereEachPixelCentreFallsInItsLattice) {
  VolumeFrame f;
  f.kind = FrameKind::kEnu;
  f.origin_lat = 45.3;
  f.origin_lon = 6.4;
  f.origin_h = 1000.0;
  Volume v = test::random_volume(5, {9, 7, 4}, f);
  v.lattice.origin = {-2000.0, -1500.0, 200.0};
  v.lattice.spacing = {500.0, 500.0, 100.0};
  io::GeoRaster r = footprint_raster(v);
  // The footprint: 4 km x 3 km at 500 m per pixel, in degrees by the WGS84 radii of curvature
  // at the origin (latitude 45.3, 1000 m up).
  const double a = 6378137.0, e2 = 0.00669437999014, phi = 45.3 * M_PI / 180.0;
  const double w = std::sqrt(1.0 - e2 * std::sin(phi) * std::sin(phi));
  const double metres_per_degree_lat = (a * (1.0 - e2) / (w * w * w) + 1000.0) * M_PI / 180.0;
  const double metres_per_degree_lon = (a / w + 1000.0) * std::cos(phi) * M_PI / 180.0;
  EXPECT_NEAR(r.dlat * metres_per_degree_lat, 500.0, 0.01);
  EXPECT_NEAR(r.dlon * metres_per_degree_lon, 500.0, 0.01);
  EXPECT_GE(r.rows, 7);
  EXPECT_GE(r.cols, 9);
  EXPECT_GT(sample_surface(v, {HeightRef::kDatum, 1250.0}, {}, r), 0u);
  const GeographicLib::LocalCartesian enu(f.origin_lat, f.origin_lon, f.origin_h);
  std::size_t inside = 0;
  for (int row = 0; row < r.rows; ++row)
    for (int c = 0; c < r.cols; ++c) {
      double e = 0, n = 0, u = 0;
      enu.Forward(r.centre_lat(row), r.centre_lon(c), 1250.0, e, n, u);
      const double want = expected_value(v, e, n, u);
      inside += !std::isnan(want);
      expect_matches(r, want, row, c);
    }
  EXPECT_GT(inside, 40u);
  // Above ground needs the ground, and then adds it.
  EXPECT_TRUE(needs_ground(v, {HeightRef::kGround, 10.0}));
  EXPECT_GT(sample_surface(v, {HeightRef::kGround, 10.0}, [](double, double) { return 1240.0; }, r), 0u);
  double e = 0, n = 0, u = 0;
  enu.Forward(r.centre_lat(r.rows / 2), r.centre_lon(r.cols / 2), 1250.0, e, n, u);
  expect_matches(r, expected_value(v, e, n, u), r.rows / 2, r.cols / 2);
}

TEST(SampleSurface, NeedsTheGroundOnlyWhenTheHeightReferencesDiffer) {
  const Volume agl = test::random_volume(6, {2, 2, 2}, geographic(HeightRef::kGround));
  const Volume datum = test::random_volume(6, {2, 2, 2}, geographic(HeightRef::kDatum));
  EXPECT_FALSE(needs_ground(agl, {HeightRef::kGround, 10}));
  EXPECT_TRUE(needs_ground(agl, {HeightRef::kDatum, 10}));
  EXPECT_TRUE(needs_ground(datum, {HeightRef::kGround, 10}));
  EXPECT_FALSE(needs_ground(datum, {HeightRef::kDatum, 10}));
  io::GeoRaster r = footprint_raster(agl);
  EXPECT_THROW(sample_surface(agl, {HeightRef::kGround, kNaN}, {}, r), std::invalid_argument);
  const Volume none = test::random_volume(6, {2, 2, 2}, VolumeFrame{});
  EXPECT_THROW(footprint_raster(none), std::invalid_argument);
}

}  // namespace
}  // namespace terravol::volume
