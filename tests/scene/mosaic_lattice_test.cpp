// app/scene/mosaic_lattice.h: points of the bundled DEM's lattice (N45E006: 1201 x 1201 samples,
// 3", north-west sample at 46 N, 6 E), worked out by hand.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "app/scene/mosaic_lattice.h"
#include "io/mosaic.h"

namespace terravol::app::scene {
namespace {

io::Mosaic bundled() { return io::Mosaic::open({std::string(TERRAVOL_SOURCE_DIR) + "/data/dem/N45E006.hgt"}); }

TEST(MosaicLattice, RowsCountSouthAndColumnsEastOfTheNorthWestSample) {
  const io::Mosaic m = bundled();
  const LatticePoint p = lattice_point(m, 45.5, 6.25);
  EXPECT_NEAR(p.row, 600.0, 1e-9);
  EXPECT_NEAR(p.col, 300.0, 1e-9);
  EXPECT_NEAR(lattice_point(m, 46.0, 6.0).col, 0.0, 1e-9);
  EXPECT_NEAR(lattice_point(m, 45.0, 7.0).row, 1200.0, 1e-9);
  EXPECT_NEAR(lattice_point(m, 45.5, 366.25).col, 300.0, 1e-9) << "longitudes modulo 360";
  EXPECT_NEAR(lattice_point(m, 45.5, -353.75).col, 300.0, 1e-9);
  EXPECT_NEAR(lattice_point(m, 45.5, 5.0).col, 359.0 * 1200.0, 1e-6) << "west of the edge is far east";
}

TEST(MosaicLattice, InsideIsTheClosedBoxOfSamples) {
  const io::Mosaic m = bundled();
  EXPECT_TRUE(inside(m, lattice_point(m, 45.0, 6.0)));
  EXPECT_TRUE(inside(m, lattice_point(m, 46.0, 7.0)));
  EXPECT_FALSE(inside(m, lattice_point(m, 46.001, 6.5)));
  EXPECT_FALSE(inside(m, lattice_point(m, 45.5, 7.001)));
  EXPECT_FALSE(inside(m, lattice_point(m, 45.5, 5.999)));
}

TEST(MosaicLattice, CamerasMayLieUpTo200KmBeyondTheDem) {
  const io::Mosaic m = bundled();
  EXPECT_DOUBLE_EQ(km_beyond(m, 45.5, 6.5), 0.0);
  EXPECT_NEAR(km_beyond(m, 47.5, 6.5), 1.5 * 111.2, 1e-9);
  EXPECT_NEAR(km_beyond(m, 45.5, 8.0), 111.2 * std::cos(45.5 * std::numbers::pi / 180.0), 1e-9);
  EXPECT_NO_THROW(require_near(m, 45.5, 6.5));
  EXPECT_NO_THROW(require_near(m, 47.5, 6.5));
  try {
    require_near(m, 48.5, 6.5);
    FAIL() << "48.5 N is 278 km north of the tile";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()),
              "camera 48.50000 N, 6.50000 E is 278.0 km beyond the DEM (45.00000 N .. 46.00000 N, 6.00000 E .. 7.00000 E; "
              "at most 200 km)");
  }
  double lat = 49.0, lon = 6.5;  // 333.6 km north: back to 199.8 km
  clamp_near_mosaic(m, lat, lon);
  EXPECT_NEAR(km_beyond(m, lat, lon), 199.8, 1e-6);
  EXPECT_DOUBLE_EQ(lon, 6.5);
}

TEST(MosaicLattice, ClampingMovesAPointToTheNearestEdge) {
  const io::Mosaic m = bundled();
  double lat = 47.0, lon = 8.0;
  clamp_to_mosaic(m, lat, lon);
  EXPECT_DOUBLE_EQ(lat, 46.0);
  EXPECT_NEAR(lon, 7.0, 1e-12);
  EXPECT_TRUE(inside(m, lattice_point(m, lat, lon)));
  lat = 44.0;
  lon = 366.5;  // 6.5 E
  clamp_to_mosaic(m, lat, lon);
  EXPECT_DOUBLE_EQ(lat, 45.0);
  EXPECT_NEAR(lon, 6.5, 1e-12);
}

TEST(MosaicLattice, TheDefaultCameraIs1500MetresAboveTheCentreLookingNorth) {
  const CameraPose p = default_pose(bundled());
  EXPECT_NEAR(p.lat, 45.5, 1e-12);
  EXPECT_NEAR(p.lon, 6.5, 1e-12);
  EXPECT_EQ(p.alt, 1500.0);
  EXPECT_EQ(p.heading_deg, 0.0);
  EXPECT_EQ(p.pitch_deg, -15.0);
}

TEST(MosaicLattice, DegreesHaveFiveDecimalsAndAHemisphere) {
  EXPECT_EQ(degrees(45.5, 'N', 'S'), "45.50000 N");
  EXPECT_EQ(degrees(-71.25, 'E', 'W'), "71.25000 W");
  EXPECT_EQ(degrees(0.0, 'E', 'W'), "0.00000 E");
}

}  // namespace
}  // namespace terravol::app::scene
