// Point queries: exact at lattice points, trilinear between them against a separate
// interpolation written out here, NaN outside and next to NaN, in each frame.
#include "volume/point_query.h"

#include <GeographicLib/LocalCartesian.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>

namespace terravol::volume {
namespace {

Volume field(VolumeFrame frame) {
  Volume v;
  v.name = "f";
  v.frame = frame;
  v.lattice.dims = {5, 4, 3};
  v.lattice.origin = {6.5, 45.5, 10.0};
  v.lattice.spacing = {0.01, 0.02, 50.0};
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 5; ++i) v.values.push_back(static_cast<float>(100.0 + 7.3 * i - 3.1 * j * j + 0.9 * k * i + 0.01 * k));
  return v;
}

// Trilinear interpolation by its definition: the weighted sum over the cell's eight corners.
double trilinear(const Volume& v, double fi, double fj, double fk) {
  const int i0 = std::min(static_cast<int>(fi), v.lattice.dims[0] - 2), j0 = std::min(static_cast<int>(fj), v.lattice.dims[1] - 2),
            k0 = std::min(static_cast<int>(fk), v.lattice.dims[2] - 2);
  const double ti = fi - i0, tj = fj - j0, tk = fk - k0;
  double sum = 0.0;
  for (int c = 0; c < 8; ++c) {
    const int di = c & 1, dj = (c >> 1) & 1, dk = (c >> 2) & 1;
    sum += (di ? ti : 1 - ti) * (dj ? tj : 1 - tj) * (dk ? tk : 1 - tk) * v.at(i0 + di, j0 + dj, k0 + dk);
  }
  return sum;
}

TEST(PointQuery, ExactAtLatticePointsOfAVolumeAboveGround) {
  const Volume v = field(parse_frame("geographic-agl"));
  const PointQuery q(v);
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 5; ++i)
        EXPECT_EQ(q.value(v.lattice.world(1, j), v.lattice.world(0, i), v.lattice.world(2, k), 1234.0), v.at(i, j, k));
}

TEST(PointQuery, TrilinearBetweenLatticePoints) {
  const Volume v = field(parse_frame("geographic-agl"));
  const PointQuery q(v);
  std::mt19937 rng(99);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int n = 0; n < 1000; ++n) {
    const double fi = 4.0 * u(rng), fj = 3.0 * u(rng), fk = 2.0 * u(rng);
    const double got = q.value(45.5 + 0.02 * fj, 6.5 + 0.01 * fi, 10.0 + 50.0 * fk, std::nan(""));
    EXPECT_NEAR(got, trilinear(v, fi, fj, fk), 1e-4) << fi << " " << fj << " " << fk;
  }
}

TEST(PointQuery, NanOutsideAndNextToNan) {
  Volume v = field(parse_frame("geographic-agl"));
  const PointQuery q(v);
  EXPECT_TRUE(std::isnan(q.value(45.4, 6.52, 20.0, 0.0)));   // south of the lattice
  EXPECT_TRUE(std::isnan(q.value(45.52, 6.52, 200.0, 0.0)));  // above it
  EXPECT_FALSE(std::isnan(q.value(45.52, 6.52, 20.0, std::nan(""))));  // the ground is not needed
  v.values[v.lattice.index(1, 1, 0)] = NAN;
  EXPECT_TRUE(std::isnan(q.value(45.53, 6.515, 20.0, 0.0)));
  EXPECT_FALSE(std::isnan(q.value(45.53, 6.535, 20.0, 0.0)));  // the next cell
}

TEST(PointQuery, DatumAndEnuFramesUseTheGround) {
  const Volume datum = field(parse_frame("geographic"));
  const PointQuery qd(datum);
  // 40 m above ground at 20 m: height 60 above the datum, lattice layer 1.
  EXPECT_EQ(qd.value(45.52, 6.52, 40.0, 20.0), datum.at(2, 1, 1));
  EXPECT_TRUE(std::isnan(qd.value(45.52, 6.52, 40.0, std::nan(""))));

  Volume enu = field(parse_frame("enu:45.5,6.5,100"));
  enu.lattice.origin = {-200.0, -300.0, -50.0};
  enu.lattice.spacing = {100.0, 200.0, 50.0};
  const PointQuery qe(enu);
  const GeographicLib::LocalCartesian lc(45.5, 6.5, 100.0);
  double lat = 0.0, lon = 0.0, h = 0.0;
  lc.Reverse(enu.lattice.world(0, 3), enu.lattice.world(1, 2), enu.lattice.world(2, 1), lat, lon, h);
  EXPECT_NEAR(qe.value(lat, lon, h - 30.0, 30.0), enu.at(3, 2, 1), 1e-3);
  const auto w = qe.world(lat, lon, h - 30.0, 30.0);
  EXPECT_NEAR(w[0], 100.0, 1e-6);
  EXPECT_NEAR(w[1], 100.0, 1e-6);
  EXPECT_NEAR(w[2], 0.0, 1e-6);
  EXPECT_THROW(PointQuery(field(VolumeFrame{})), std::invalid_argument);
}

}  // namespace
}  // namespace terravol::volume
