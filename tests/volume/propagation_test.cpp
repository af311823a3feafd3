// The built-in propagation model: exact small cases, physics checks on synthetic terrain, and
// seeded properties of the Deygout construction.
#include "volume/propagation.h"

#include <GeographicLib/Geodesic.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <stdexcept>

#include "io/mosaic.h"
#include "shared_data.h"
#include "volume/itm_reference.h"
#include "volume_test_util.h"
#include "io/scene_frame.h"
#include "volume/readers.h"
#include "volume/vdb_write.h"

namespace terravol::volume {
namespace {

using test::synthetic_dem;

constexpr double kLambda900 = 299792458.0 / 900e6;

double geodesic_m(double lat1, double lon1, double lat2, double lon2) {
  double s = 0.0;
  GeographicLib::Geodesic::WGS84().Inverse(lat1, lon1, lat2, lon2, s);
  return s;
}

// The lattice column of the transmitter.
std::pair<int, int> tx_column(const Volume& v, const Transmitter& tx) {
  const auto& l = v.lattice;
  return {static_cast<int>(std::lround((tx.lon - l.origin[0]) / l.spacing[0])),
          static_cast<int>(std::lround((tx.lat - l.origin[1]) / l.spacing[1]))};
}

const Transmitter kFlatTx{45.5, 6.5, 30.0, 900.0, std::nullopt, {}, {}};

TEST(FreeSpace, MatchesTheTextbookFormula) {
  for (double f : {30.0, 144.0, 900.0, 2400.0, 10000.0}) {
    for (double d_km : {0.1, 1.0, 7.5, 20.0, 150.0}) {
      EXPECT_NEAR(free_space_loss_db(d_km * 1000.0, f), 32.45 + 20.0 * std::log10(f) + 20.0 * std::log10(d_km), 0.01);
    }
  }
}

TEST(KnifeEdge, ItuFormulaValues) {
  EXPECT_EQ(knife_edge_loss_db(-0.78), 0.0);
  EXPECT_EQ(knife_edge_loss_db(-3.0), 0.0);
  EXPECT_NEAR(knife_edge_loss_db(0.0), 6.03, 0.01);   // grazing: about 6 dB
  EXPECT_NEAR(knife_edge_loss_db(1.0), 13.93, 0.01);
  EXPECT_NEAR(knife_edge_loss_db(-0.7), 0.53, 0.01);
  // Large v: J(v) tends to 13 + 20 log10(v).
  EXPECT_NEAR(knife_edge_loss_db(20.0), 13.0 + 20.0 * std::log10(20.0), 0.15);
}

TEST(Diffraction, SingleKnifeEdgeEqualsJOfV) {
  PathProfile p;
  p.distance_m = 10000.0;
  p.tx_height_m = 50.0;
  p.rx_height_m = 70.0;
  for (double top : {20.0, 55.0, 80.0, 300.0}) {
    p.d_m = {4000.0};
    p.z_m = {top};
    const double k = 4.0 / 3.0;
    const double bulge = 4000.0 * 6000.0 / (2.0 * k * 6371000.0);
    const double h = top + bulge - (50.0 + 20.0 * 0.4);
    const double v = h * std::sqrt(2.0 * 10000.0 / (kLambda900 * 4000.0 * 6000.0));
    const double expected = v > -0.78 ? 6.9 + 20.0 * std::log10(std::sqrt((v - 0.1) * (v - 0.1) + 1.0) + v - 0.1) : 0.0;
    EXPECT_NEAR(diffraction_loss_db(p, 900.0, k), expected, 1e-9) << top;
    EXPECT_NEAR(path_loss_db(p, 900.0, k), free_space_loss_db(std::hypot(10000.0, 20.0), 900.0) + expected, 1e-9);
  }
}

TEST(Diffraction, ClearPathHasNone) {
  PathProfile p;
  p.distance_m = 20000.0;
  p.tx_height_m = p.rx_height_m = 300.0;
  for (int i = 1; i < 200; ++i) {
    p.d_m.push_back(i * 100.0);
    p.z_m.push_back(0.0);
  }
  EXPECT_EQ(diffraction_loss_db(p, 900.0), 0.0);
  // With no curvature allowance the bulge of a 20 km path (about 6 m at k = 4/3) is gone;
  // low antennas then see the ground bulge: some loss appears as k shrinks.
  p.tx_height_m = p.rx_height_m = 8.0;
  EXPECT_GT(diffraction_loss_db(p, 900.0, 0.5), diffraction_loss_db(p, 900.0, 4.0 / 3.0));
}

TEST(Diffraction, DeygoutPrincipalPlusSecondaryEdges) {
  // Two equal ridges with valleys around them: the principal is one of them, the other is the
  // secondary edge of its sub-path; the total is J(v_principal) + J(v_secondary).
  PathProfile p;
  p.distance_m = 12000.0;
  p.tx_height_m = p.rx_height_m = 10.0;
  p.d_m = {2000.0, 4000.0, 6000.0, 8000.0, 10000.0};
  p.z_m = {0.0, 60.0, 0.0, 60.0, 0.0};
  const double k = 1e12;  // no bulge: the geometry is exactly as written
  const double v1 = 50.0 * std::sqrt(2.0 * 12000.0 / (kLambda900 * 4000.0 * 8000.0));
  // Sub-path from the ridge at 4 km (the principal; the one at 8 km is its mirror image) to the
  // receiver: the other ridge is 60 - 35 = 25 m above the line from (4000, 60) to (12000, 10).
  const double v2 = 25.0 * std::sqrt(2.0 * 8000.0 / (kLambda900 * 4000.0 * 4000.0));
  EXPECT_NEAR(diffraction_loss_db(p, 900.0, k, 1), knife_edge_loss_db(v1), 1e-9);
  EXPECT_NEAR(diffraction_loss_db(p, 900.0, k, 2), knife_edge_loss_db(v1) + knife_edge_loss_db(v2), 1e-9);
}

TEST(Diffraction, SamplesJoinedToAnEdgeAreItsObstacle) {
  // A plateau sampled every 50 m: its far samples graze the sub-path from its near edge, but
  // they are the same obstacle, so they add nothing; a separate ridge behind a valley does.
  PathProfile p;
  p.distance_m = 10000.0;
  p.tx_height_m = p.rx_height_m = 10.0;
  for (double d = 3000.0; d <= 3500.0; d += 50.0) {
    p.d_m.push_back(d);
    p.z_m.push_back(100.0);
  }
  const double k = 1e12;
  const double one_edge = diffraction_loss_db(p, 900.0, k, 1);
  EXPECT_GT(one_edge, 20.0);
  EXPECT_EQ(diffraction_loss_db(p, 900.0, k, 2), one_edge);
  EXPECT_EQ(diffraction_loss_db(p, 900.0, k, 3), one_edge);
  p.d_m.push_back(5000.0);  // a valley, then a second ridge
  p.z_m.push_back(0.0);
  p.d_m.push_back(7000.0);
  p.z_m.push_back(80.0);
  EXPECT_GT(diffraction_loss_db(p, 900.0, k, 2), one_edge + 5.0);
}

TEST(DiffractionProperty, SymmetricNonNegativeAndGrowingWithDepth) {
  std::mt19937 rng(20240607);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int trial = 0; trial < 2000; ++trial) {
    PathProfile p;
    p.distance_m = 100.0 + 50000.0 * unit(rng);
    const int n = static_cast<int>(60 * unit(rng));
    const double relief = 1000.0 * unit(rng);
    for (int i = 1; i <= n; ++i) {
      p.d_m.push_back(p.distance_m * i / (n + 1));
      p.z_m.push_back(relief * unit(rng));
    }
    p.tx_height_m = relief * unit(rng) + 30.0;
    p.rx_height_m = relief * unit(rng) + 1.0;
    const double f = 50.0 + 5000.0 * unit(rng);
    PathProfile q;
    q.distance_m = p.distance_m;
    q.tx_height_m = p.rx_height_m;
    q.rx_height_m = p.tx_height_m;
    for (int i = n - 1; i >= 0; --i) {
      q.d_m.push_back(p.distance_m - p.d_m[i]);
      q.z_m.push_back(p.z_m[i]);
    }
    double previous = 0.0;
    for (int depth = 1; depth <= 4; ++depth) {
      const double forward = diffraction_loss_db(p, f, 4.0 / 3.0, depth);
      const double backward = diffraction_loss_db(q, f, 4.0 / 3.0, depth);
      ASSERT_TRUE(std::isfinite(forward)) << trial;
      ASSERT_NEAR(forward, backward, 1e-7 * (1.0 + forward)) << "trial " << trial << " depth " << depth;
      ASSERT_GE(forward, previous - 1e-12) << "trial " << trial << " depth " << depth;
      previous = forward;
    }
    ASSERT_NEAR(path_loss_db(p, f), path_loss_db(q, f), 1e-7 * path_loss_db(p, f)) << trial;
  }
}

TEST(Rf, FreeSpaceOverFlatGroundAtLineOfSight) {
  const io::Grid flat = synthetic_dem([](double, double) { return 0.0; });
  Transmitter tx{45.5, 6.5, 200.0, 900.0, std::nullopt, {}, {}};
  RfGrid grid;
  grid.radius_km = 8.0;
  grid.spacing_arcsec = 30.0;
  grid.heights_agl = {200.0};  // the transmitter's height: the path is level and clear
  const RfResult r = compute_rf(flat, tx, grid);
  const Volume& v = r.path_loss;
  const auto [it, jt] = tx_column(v, tx);
  int checked = 0;
  for (int j = 0; j < v.lattice.dims[1]; ++j) {
    for (int i = 0; i < v.lattice.dims[0]; ++i) {
      if (i == it && j == jt) continue;
      const double d_km = geodesic_m(tx.lat, tx.lon, v.lattice.world(1, j), v.lattice.world(0, i)) / 1000.0;
      EXPECT_NEAR(v.at(i, j, 0), 32.45 + 20.0 * std::log10(900.0) + 20.0 * std::log10(d_km), 0.01) << i << " " << j;
      ++checked;
    }
  }
  EXPECT_GT(checked, 400);
  EXPECT_NEAR(v.at(it, jt, 0), free_space_loss_db(1.0, 900.0), 1e-4);  // same point: clamped to 1 m
}

// Flat ground 100 m up, a transmitter 30 m above it, receivers at 2, 52 and 102 m, 25 km.
RfResult flat_ground_volume(const RfOptions& options) {
  const io::Grid flat = synthetic_dem([](double, double) { return 100.0; });
  RfGrid grid;
  grid.radius_km = 25.0;
  grid.spacing_arcsec = 15.0;
  grid.heights_agl = {2.0, 52.0, 102.0};
  return compute_rf(flat, kFlatTx, grid, options);
}

// The loss grows along the transmitter's row (east and west) and column (north) from `first`
// lattice steps out. Beyond the radio horizon of 30 m and 2 m antennas (about 28 km at
// k = 4/3) the far corner at 2 m is more than `excess` dB below free space, and higher
// receivers see less loss.
void expect_loss_grows_over_flat_ground(const Volume& v, int first, double excess) {
  const auto [it, jt] = tx_column(v, kFlatTx);
  for (int k = 0; k < 3; ++k) {
    for (int i = it + first; i < v.lattice.dims[0]; ++i) EXPECT_GT(v.at(i, jt, k), v.at(i - 1, jt, k)) << i << " " << k;
    for (int i = it - first; i >= 0; --i) EXPECT_GT(v.at(i, jt, k), v.at(i + 1, jt, k)) << i << " " << k;
    for (int j = jt + first; j < v.lattice.dims[1]; ++j) EXPECT_GT(v.at(it, j, k), v.at(it, j - 1, k)) << j << " " << k;
  }
  const int far = v.lattice.dims[0] - 1;
  const double d = geodesic_m(kFlatTx.lat, kFlatTx.lon, v.lattice.world(1, 0), v.lattice.world(0, far));
  EXPECT_GT(v.at(far, 0, 0), free_space_loss_db(d, 900.0) + excess);
  EXPECT_LT(v.at(far, 0, 2), v.at(far, 0, 0));
}

TEST(Rf, LossGrowsWithDistanceOverFlatGround) {
  expect_loss_grows_over_flat_ground(flat_ground_volume(RfOptions{}).path_loss, 1, 6.0);
}

// A 400 m north-south ridge between 6.55 and 6.56 E, about 4 km east of a transmitter 30 m up;
// receivers at 10..810 m every 200 m, 12 km.
Volume ridge_volume(const RfOptions& options) {
  const io::Grid dem = synthetic_dem([](double, double lon) { return lon >= 6.55 && lon <= 6.56 ? 400.0 : 0.0; });
  RfGrid grid;
  grid.radius_km = 12.0;
  grid.spacing_arcsec = 30.0;
  grid.heights_agl = {10.0, 210.0, 410.0, 610.0, 810.0};
  return compute_rf(dem, kFlatTx, grid, options).path_loss;
}

// Deep shadow at the east edge, falling as the receiver rises out of it, and every column east
// of the ridge in its shadow at 10 m.
void expect_shadow_behind_the_ridge(const Volume& v) {
  const Transmitter& tx = kFlatTx;
  const auto [it, jt] = tx_column(v, tx);
  const int east = v.lattice.dims[0] - 1;
  ASSERT_GT(v.lattice.world(0, east), 6.6);
  const double d_east = geodesic_m(tx.lat, tx.lon, tx.lat, v.lattice.world(0, east));
  EXPECT_GT(v.at(east, jt, 0), free_space_loss_db(d_east, 900.0) + 20.0);
  for (int k = 1; k < 5; ++k) EXPECT_LT(v.at(east, jt, k), v.at(east, jt, k - 1)) << k;
  for (int i = it; i < v.lattice.dims[0]; ++i) {
    if (v.lattice.world(0, i) <= 6.565) continue;
    const double d = geodesic_m(tx.lat, tx.lon, tx.lat, v.lattice.world(0, i));
    EXPECT_GT(v.at(i, jt, 0), free_space_loss_db(d, 900.0) + 15.0) << i;
  }
}

TEST(Rf, LossGrowsBehindARidge) {
  const Volume v = ridge_volume(RfOptions{});
  expect_shadow_behind_the_ridge(v);
  // The open side: the bulge of flat ground leaves about half a Fresnel zone of clearance at
  // 12 km for 30 m and 10 m antennas, so the loss is close to free space.
  const auto [it, jt] = tx_column(v, kFlatTx);
  const double d_west = geodesic_m(kFlatTx.lat, kFlatTx.lon, kFlatTx.lat, v.lattice.world(0, 0));
  EXPECT_NEAR(v.at(0, jt, 0), free_space_loss_db(std::hypot(d_west, 20.0), 900.0), 2.0);
}

TEST(Rf, SignalIsEirpMinusPathLoss) {
  const io::Grid dem = synthetic_dem([](double lat, double lon) { return 500.0 + 300.0 * std::sin(40.0 * lat) * std::cos(50.0 * lon); });
  const Transmitter tx{45.5, 6.5, 30.0, 450.0, 50.0, {}, {}};
  RfGrid grid;
  grid.radius_km = 5.0;
  grid.spacing_arcsec = 20.0;
  grid.heights_agl = {0.0, 100.0};
  const RfResult r = compute_rf(dem, tx, grid);
  ASSERT_TRUE(r.signal);
  EXPECT_EQ(r.signal->name, "signal_dbm");
  EXPECT_EQ(r.signal->units, "dBm");
  EXPECT_EQ(r.signal->lattice, r.path_loss.lattice);
  const double eirp = 10.0 * std::log10(50.0) + 30.0 + 2.15;  // 50 W ERP = 46.99 dBm, + 2.15 dB dipole gain
  for (std::size_t n = 0; n < r.path_loss.values.size(); ++n) {
    EXPECT_NEAR(r.signal->values[n], eirp - r.path_loss.values[n], 1e-4);
  }
  EXPECT_FALSE(compute_rf(dem, Transmitter{45.5, 6.5, 30.0, 450.0, std::nullopt, {}, {}}, grid).signal);
}

TEST(Rf, LatticeIsCentredOnTheTransmitterAndClippedToTheDem) {
  const io::Grid flat = synthetic_dem([](double, double) { return 0.0; });
  const Transmitter centre{45.5, 6.5, 10.0, 900.0, std::nullopt, {}, {}};
  RfGrid grid;
  grid.radius_km = 20.0;
  grid.heights_agl = {};
  const RfResult r = compute_rf(flat, centre, grid);
  const Lattice& l = r.path_loss.lattice;
  EXPECT_EQ(l.spacing[0], 6.0 / 3600.0);  // default spacing: 2 x 3" for a 20 km radius
  EXPECT_EQ(l.dims[2], 41);                // default heights 0, 50, ..., 2000
  EXPECT_EQ(l.world(2, 40), 2000.0);
  EXPECT_EQ(l.dims[0] % 2, 1);
  EXPECT_EQ(l.dims[1] % 2, 1);
  EXPECT_NEAR(l.world(0, l.dims[0] / 2), 6.5, 1e-12);
  EXPECT_NEAR(l.world(1, l.dims[1] / 2), 45.5, 1e-12);
  EXPECT_NEAR((l.world(1, l.dims[1] - 1) - 45.5) * 111132.0, 20000.0, 200.0);
  EXPECT_TRUE(r.notes.empty());
  EXPECT_EQ(r.path_loss.frame, parse_frame("geographic-agl"));

  const Transmitter corner{45.05, 6.03, 10.0, 900.0, std::nullopt, {}, {}};
  const RfResult c = compute_rf(flat, corner, grid);
  ASSERT_EQ(c.notes.size(), 1u);
  EXPECT_GE(c.path_loss.lattice.origin[0], 6.0);
  EXPECT_GE(c.path_loss.lattice.origin[1], 45.0);
  const auto [i, j] = tx_column(c.path_loss, corner);
  EXPECT_NEAR(c.path_loss.lattice.world(0, i), corner.lon, 1e-12);
  EXPECT_NEAR(c.path_loss.lattice.world(1, j), corner.lat, 1e-12);
}

TEST(Rf, RejectsBadParameters) {
  const io::Grid flat = synthetic_dem([](double, double) { return 0.0; });
  const Transmitter tx{45.5, 6.5, 10.0, 900.0, std::nullopt, {}, {}};
  RfGrid grid;
  grid.radius_km = 0.0;
  EXPECT_THROW(compute_rf(flat, tx, grid), std::invalid_argument);
  grid.radius_km = 5.0;
  grid.heights_agl = {10.0, 20.0, 40.0};
  EXPECT_THROW(compute_rf(flat, tx, grid), std::invalid_argument);
  grid.heights_agl = {10.0};
  EXPECT_THROW(compute_rf(flat, Transmitter{10.0, 10.0, 10.0, 900.0, std::nullopt, {}, {}}, grid), std::invalid_argument);
  EXPECT_THROW(compute_rf(flat, Transmitter{45.5, 6.5, 10.0, -5.0, std::nullopt, {}, {}}, grid), std::invalid_argument);
  EXPECT_THROW(compute_rf(flat, Transmitter{45.5, 6.5, 10.0, 900.0, 0.0, {}, {}}, grid), std::invalid_argument);
}

TEST(RfPath, EqualsComputeRfAtItsLatticePoints) {
  const io::Grid dem = synthetic_dem([](double lat, double lon) { return 500.0 + 300.0 * std::sin(40.0 * lat) * std::cos(50.0 * lon); });
  const Transmitter tx{45.5, 6.5, 30.0, 900.0, std::nullopt, {}, {}};
  RfGrid grid;
  grid.radius_km = 6.0;
  grid.spacing_arcsec = 20.0;
  grid.heights_agl = {0.0, 100.0, 200.0};
  const Volume v = compute_rf(dem, tx, grid).path_loss;
  std::mt19937 rng(1717);
  for (int trial = 0; trial < 300; ++trial) {
    const int i = std::uniform_int_distribution<int>(0, v.lattice.dims[0] - 1)(rng);
    const int j = std::uniform_int_distribution<int>(0, v.lattice.dims[1] - 1)(rng);
    const int k = std::uniform_int_distribution<int>(0, 2)(rng);
    const RfPath p = rf_path(dem, tx, v.lattice.world(1, j), v.lattice.world(0, i), v.lattice.world(2, k));
    ASSERT_EQ(static_cast<float>(p.path_loss_db), v.at(i, j, k)) << i << " " << j << " " << k;
    EXPECT_NEAR(p.path_loss_db, p.free_space_db + p.diffraction_db, 1e-9);
    EXPECT_NEAR(p.diffraction_db, diffraction_loss_db(p.profile, 900.0), 1e-9);
    double edges = 0.0;
    for (std::size_t e = 0; e < p.edges.size(); ++e) {
      edges += p.edges[e].loss_db;
      if (e > 0) {
        EXPECT_LT(p.edges[e - 1].sample, p.edges[e].sample);
      }
    }
    EXPECT_NEAR(edges, p.diffraction_db, 1e-9);
    EXPECT_LE(p.edges.size(), 3u);
  }
}

TEST(RfPath, DepartureIsTheSteepestLegAboveTheTransmittersHorizon) {
  // Over flat ground the path is clear: the departure is the line to the receiver, less the
  // Earth's curvature, by hand: atan((h_rx - h_tx) / D) - atan(D / (2 k a)).
  const io::Grid flat = synthetic_dem([](double, double) { return 100.0; });
  const Transmitter tx{45.5, 6.5, 40.0, 900.0, std::nullopt, {}, {}};
  const RfPath clear = rf_path(flat, tx, 45.5, 6.6, 300.0);
  ASSERT_TRUE(clear.edges.empty());
  const double D = geodesic_m(45.5, 6.5, 45.5, 6.6);
  const double two_ka = 2.0 * 4.0 / 3.0 * 6371000.0;
  EXPECT_NEAR(clear.departure_deg, (std::atan(260.0 / D) - std::atan(D / two_ka)) * 180.0 / M_PI, 1e-9);
  EXPECT_NEAR(clear.azimuth_deg, 90.0, 0.1);
  // Behind a 400 m ridge 4 km east the path leaves towards the ridge's top, well above the
  // line to a low receiver beyond it.
  const io::Grid ridge = synthetic_dem([](double, double lon) { return lon >= 6.55 && lon <= 6.56 ? 400.0 : 0.0; });
  const RfPath behind = rf_path(ridge, tx, 45.5, 6.65, 10.0);
  ASSERT_FALSE(behind.edges.empty());
  const std::size_t e = behind.edges.front().sample;
  const double d = behind.profile.d_m[e], Db = behind.profile.distance_m;
  const double raised = behind.profile.z_m[e] + d * (Db - d) / two_ka;
  EXPECT_NEAR(behind.departure_deg, (std::atan((raised - 40.0) / d) - std::atan(Db / two_ka)) * 180.0 / M_PI, 1e-9);
  EXPECT_GT(behind.departure_deg, 4.0);
}

// Over flat ground every path is clear, so with either model the departure is the line to the
// receiver, and the pattern's attenuation is the model's loss with it less the loss without.
void expect_pattern_attenuation_along_the_departure(const RfOptions& options) {
  const io::Grid flat = synthetic_dem([](double, double) { return 100.0; });
  Transmitter tx{45.5, 6.5, 40.0, 900.0, 10.0, {}, {}};
  AntennaPattern pattern;
  pattern.azimuth = parse_az("0\n0 1\n90 0.5\n180 0.1\n270 0.5\n", "t.az").first;
  pattern.elevation = parse_el("0 0\n-10 1\n0 1\n10 0.2\n", "t.el").cut;
  RfGrid grid;
  grid.radius_km = 3.0;
  grid.spacing_arcsec = 30.0;
  grid.heights_agl = {10.0, 510.0};
  const Volume plain = compute_rf(flat, tx, grid, options).path_loss;
  tx.antenna = pattern;
  const RfResult with = compute_rf(flat, tx, grid, options);
  EXPECT_NE(with.path_loss.attributes.at("antenna_pattern").find("t.az:t.el"), std::string::npos);
  const double two_ka = 2.0 * 4.0 / 3.0 * 6371000.0;
  const Lattice& l = plain.lattice;
  int checked = 0;
  for (int k = 0; k < 2; ++k) {
    for (int j = 0; j < l.dims[1]; ++j) {
      for (int i = 0; i < l.dims[0]; ++i) {
        double D = 0.0, azi1 = 0.0, azi2 = 0.0;
        GeographicLib::Geodesic::WGS84().Inverse(45.5, 6.5, l.world(1, j), l.world(0, i), D, azi1, azi2);
        if (D < 1.0) continue;
        // Flat ground, clear paths: the departure is the line to the receiver (by hand).
        const double departure = (std::atan((l.world(2, k) - 40.0) / D) - std::atan(D / two_ka)) * 180.0 / M_PI;
        const double gain = pattern.gain_db(azi1 < 0.0 ? azi1 + 360.0 : azi1, departure);
        EXPECT_NEAR(with.path_loss.at(i, j, k) - plain.at(i, j, k), -gain, 2e-4) << i << " " << j << " " << k;
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 100);
  // The signal follows: ERP in the pattern's strongest direction, less the pattern elsewhere.
  EXPECT_NEAR(with.signal->values[5] + with.path_loss.values[5], 10.0 * std::log10(10.0) + 30.0 + 2.15, 1e-3);
}

TEST(RfPath, AntennaPatternAddsItsAttenuationAlongTheDeparture) { expect_pattern_attenuation_along_the_departure({}); }

RfOptions itm_options() {
  RfOptions o;
  o.model = RfModel::kItm;
  return o;
}

// Rolling hills of +-250 m, and a transmitter 20 m above them at 450 MHz.
io::Grid hilly_dem() {
  return synthetic_dem([](double lat, double lon) { return 800.0 + 250.0 * std::sin(30.0 * lat) * std::cos(45.0 * lon); });
}
const Transmitter kHillyTx{45.5, 6.5, 20.0, 450.0, std::nullopt, {}, {}};

TEST(RfItm, EachColumnIsItmOverItsOwnProfile) {
  const io::Grid dem = hilly_dem();
  const Transmitter tx = kHillyTx;
  RfGrid grid;
  grid.radius_km = 6.0;
  grid.spacing_arcsec = 30.0;
  grid.heights_agl = {2.0, 52.0, 102.0};
  RfOptions o = itm_options();
  o.itm.climate = ItmClimate::kMaritimeTemperateOverLand;
  o.itm.time = 0.9;
  const Volume v = compute_rf(dem, tx, grid, o).path_loss;
  EXPECT_NE(v.attributes.at("model").find("Longley-Rice ITM"), std::string::npos);
  EXPECT_FALSE(v.attributes.contains("k_factor"));
  const io::SceneFrame frame(tx.lat, tx.lon);
  const double step = std::min(dem.georef.dx * frame.metres_per_degree_lon(), dem.georef.dy * frame.metres_per_degree_lat());
  const std::pair<int, int> columns[] = {{0, 0}, {3, 7}, {v.lattice.dims[0] - 1, 5}, {12, v.lattice.dims[1] - 1}};
  for (const auto& [i, j] : columns) {
    TerrainProfile profile;
    sample_profile(dem, tx.lat, tx.lon, v.lattice.world(1, j), v.lattice.world(0, i), step, profile);
    const double spacing = profile.distance_m / static_cast<double>(profile.ground_m.size() - 1);
    for (int k = 0; k < 3; ++k) {
      const ItmLoss expected = itm_point_to_point(profile.ground_m, spacing, tx.height_agl, grid.heights_agl[k], tx.frequency_mhz, o.itm);
      EXPECT_FLOAT_EQ(v.at(i, j, k), static_cast<float>(expected.loss_db)) << i << " " << j << " " << k;
    }
  }
}

TEST(RfItm, AntennaPatternAddsItsAttenuationAlongTheDeparture) {
  expect_pattern_attenuation_along_the_departure(itm_options());
}

// Every point of seeded random columns of `rf --model itm` volumes equals the straightforward
// evaluation of ITM on that point alone (volume/itm_reference.h: no work shared between the
// heights, the profile's searches and fits done afresh) on the column's own profile, to the
// float the volume stores: over the rolling hills, and over the Utah tiles (the bench's
// lattice: 3", 31 heights 10..310 m, 900 MHz) from the valley and from Farnsworth Peak.
void expect_columns_equal_the_straightforward_itm(const io::Grid& dem, const Transmitter& tx, const RfGrid& grid,
                                                  const RfOptions& o, int columns, unsigned seed) {
  const Volume v = compute_rf(dem, tx, grid, o).path_loss;
  const io::SceneFrame frame(tx.lat, tx.lon);
  const double step = std::min(dem.georef.dx * frame.metres_per_degree_lon(), dem.georef.dy * frame.metres_per_degree_lat());
  std::mt19937 rng(seed);
  int checked = 0;
  double worst = 0.0;
  for (int c = 0; c < columns; ++c) {
    const int i = std::uniform_int_distribution<int>(0, v.lattice.dims[0] - 1)(rng);
    const int j = std::uniform_int_distribution<int>(0, v.lattice.dims[1] - 1)(rng);
    TerrainProfile profile;
    sample_profile(dem, tx.lat, tx.lon, v.lattice.world(1, j), v.lattice.world(0, i), step, profile);
    if (profile.distance_m < 1.0) continue;  // the transmitter's own column
    const double spacing = profile.distance_m / static_cast<double>(profile.ground_m.size() - 1);
    for (int k = 0; k < v.lattice.dims[2]; ++k) {
      const double expected =
          reference::itm_reference(profile.ground_m, spacing, tx.height_agl, v.lattice.world(2, k), tx.frequency_mhz, o.itm).loss_db;
      const float rounded = static_cast<float>(expected);
      const double half_ulp = 0.5 * (std::nextafter(rounded, INFINITY) - rounded);
      ASSERT_NEAR(v.at(i, j, k), expected, half_ulp + 1e-6) << "column " << i << " " << j << ", height " << v.lattice.world(2, k);
      worst = std::max(worst, std::abs(v.at(i, j, k) - expected));
      ++checked;
    }
  }
  EXPECT_GE(checked, (columns - 1) * v.lattice.dims[2]);
  std::printf("%d points, largest difference %.3g dB (the volume holds floats)\n", checked, worst);
}

RfGrid bench_like_grid(double radius_km, double spacing_arcsec) {
  RfGrid grid;
  grid.radius_km = radius_km;
  grid.spacing_arcsec = spacing_arcsec;
  for (int k = 0; k < 31; ++k) grid.heights_agl.push_back(10.0 + 10.0 * k);
  return grid;
}

TEST(RfItm, ColumnsEqualTheStraightforwardEvaluationOverHills) {
  RfOptions o = itm_options();
  o.itm.climate = ItmClimate::kMaritimeTemperateOverLand;
  o.itm.time = 0.9;
  expect_columns_equal_the_straightforward_itm(hilly_dem(), kHillyTx, bench_like_grid(6.0, 15.0), o, 120, 1919);
}

TEST(RfItm, ColumnsEqualTheStraightforwardEvaluationOverTheUtahTiles) {
  const auto tiles = test::shared_dem("utah_sdf");
  TERRAVOL_REQUIRE_SHARED(tiles);
  const io::Mosaic mosaic = io::Mosaic::open({tiles});
  const RfGrid grid = bench_like_grid(8.0, 3.0);
  for (const Transmitter& tx : {Transmitter{40.76, -111.89, 30.0, 900.0, std::nullopt, {}, {}},
                               Transmitter{40.6589, -112.2019, 30.0, 900.0, std::nullopt, {}, {}}}) {
    SCOPED_TRACE(std::to_string(tx.lat) + ", " + std::to_string(tx.lon));
    const RfWindow window = read_rf_window(mosaic, rf_area(tx, grid.radius_km));
    expect_columns_equal_the_straightforward_itm(window.grid, tx, grid, itm_options(), 150, 4242);
  }
}

// rf_path with ITM is compute_rf's value at the lattice point, its terms add up, it has no
// knife edges, and its departure is the steepest line over the profile (by hand from the
// profile it returns: the terrain raised by the k-factor bulge).
TEST(RfItm, PathEqualsComputeRfAndDepartsAlongTheSteepestLineOverTheTerrain) {
  const io::Grid dem = hilly_dem();
  const Transmitter tx = kHillyTx;
  RfGrid grid;
  grid.radius_km = 6.0;
  grid.spacing_arcsec = 30.0;
  grid.heights_agl = {2.0, 102.0};
  const RfOptions o = itm_options();
  const Volume v = compute_rf(dem, tx, grid, o).path_loss;
  const double two_ka = 2.0 * 4.0 / 3.0 * 6371000.0;
  std::mt19937 rng(1919);
  int checked = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const int i = std::uniform_int_distribution<int>(0, v.lattice.dims[0] - 1)(rng);
    const int j = std::uniform_int_distribution<int>(0, v.lattice.dims[1] - 1)(rng);
    const int k = std::uniform_int_distribution<int>(0, 1)(rng);
    if (std::isnan(v.at(i, j, k))) continue;  // the transmitter's column
    const RfPath p = rf_path(dem, tx, v.lattice.world(1, j), v.lattice.world(0, i), v.lattice.world(2, k), o);
    ASSERT_EQ(static_cast<float>(p.path_loss_db), v.at(i, j, k)) << i << " " << j << " " << k;
    EXPECT_TRUE(p.edges.empty());
    EXPECT_NEAR(p.path_loss_db, p.free_space_db + p.diffraction_db, 1e-9);
    const PathProfile& q = p.profile;
    double slope = (q.rx_height_m - q.tx_height_m) / q.distance_m;
    for (std::size_t m = 0; m < q.d_m.size(); ++m) {
      slope = std::max(slope, (q.z_m[m] + q.d_m[m] * (q.distance_m - q.d_m[m]) / two_ka - q.tx_height_m) / q.d_m[m]);
    }
    EXPECT_NEAR(p.departure_deg, (std::atan(slope) - std::atan(q.distance_m / two_ka)) * 180.0 / M_PI, 1e-9);
    ++checked;
  }
  EXPECT_GT(checked, 50);
}

TEST(Rf, DiscLeavesTheColumnsBeyondTheRadiusNaNAndTheOthersAsTheBox) {
  const io::Grid dem = hilly_dem();
  const Transmitter tx = kHillyTx;
  RfGrid grid;
  grid.radius_km = 5.0;
  grid.spacing_arcsec = 15.0;
  grid.heights_agl = {2.0, 52.0};
  for (const RfModel model : {RfModel::kDeygout, RfModel::kItm}) {
    RfOptions o;
    o.model = model;
    const RfResult box = compute_rf(dem, tx, grid, o);
    grid.disc = true;
    const RfResult disc = compute_rf(dem, tx, grid, o);
    grid.disc = false;
    const Lattice& l = box.path_loss.lattice;
    ASSERT_EQ(disc.path_loss.lattice.dims, l.dims);
    std::size_t inside = 0;
    for (int j = 0; j < l.dims[1]; ++j)
      for (int i = 0; i < l.dims[0]; ++i) {
        const bool in = geodesic_m(tx.lat, tx.lon, l.world(1, j), l.world(0, i)) <= 5000.0;
        inside += in;
        for (int k = 0; k < 2; ++k) {
          if (in) {
            ASSERT_EQ(std::isnan(disc.path_loss.at(i, j, k)), std::isnan(box.path_loss.at(i, j, k)));
            if (!std::isnan(box.path_loss.at(i, j, k))) {
              ASSERT_EQ(disc.path_loss.at(i, j, k), box.path_loss.at(i, j, k));
            }
          } else {
            ASSERT_TRUE(std::isnan(disc.path_loss.at(i, j, k))) << i << " " << j;
          }
        }
      }
    EXPECT_EQ(disc.columns, inside);
    EXPECT_NEAR(static_cast<double>(inside) / static_cast<double>(l.dims[0] * l.dims[1]), M_PI / 4.0, 0.03);
  }
}

TEST(RfItm, LossGrowsWithDistanceOverFlatGroundAndHasNoValueAtTheTransmitter) {
  const RfResult r = flat_ground_volume(itm_options());
  expect_loss_grows_over_flat_ground(r.path_loss, 2, 10.0);
  const auto [it, jt] = tx_column(r.path_loss, kFlatTx);
  for (int k = 0; k < 3; ++k) EXPECT_TRUE(std::isnan(r.path_loss.at(it, jt, k)));
  ASSERT_FALSE(r.notes.empty());
  EXPECT_EQ(r.notes[0], "ITM has no value at the transmitter's own column (NaN)");
}

TEST(RfItm, LossGrowsBehindARidge) { expect_shadow_behind_the_ridge(ridge_volume(itm_options())); }

TEST(RfItm, RejectsParametersOutsideTheModelsRange) {
  const io::Grid flat = synthetic_dem([](double, double) { return 0.0; });
  RfGrid grid;
  grid.radius_km = 2.0;
  grid.heights_agl = {10.0};
  auto message = [&](const Transmitter& tx, const RfGrid& g, const RfOptions& o) {
    try {
      compute_rf(flat, tx, g, o);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  RfOptions o = itm_options();
  EXPECT_EQ(message(Transmitter{45.5, 6.5, 10.0, 10.0, std::nullopt, {}, {}}, grid, o),
            "ITM frequency 10 MHz: must be within [20, 20000] MHz");
  EXPECT_EQ(message(Transmitter{45.5, 6.5, 0.2, 900.0, std::nullopt, {}, {}}, grid, o),
            "transmitter height 0.2: ITM takes antenna heights within [0.5, 3000] m above ground");
  RfGrid low = grid;
  low.heights_agl = {0.0, 50.0};
  EXPECT_EQ(message(Transmitter{45.5, 6.5, 10.0, 900.0, std::nullopt, {}, {}}, low, o),
            "height 0: ITM takes antenna heights within [0.5, 3000] m above ground");
  o.itm.climate = static_cast<ItmClimate>(0);
  EXPECT_EQ(message(Transmitter{45.5, 6.5, 10.0, 900.0, std::nullopt, {}, {}}, grid, o).rfind("ITM climate 0: must be within 1..7", 0), 0u);
  // The default heights start at 10 m for ITM, 0 for Deygout.
  RfGrid defaults;
  defaults.radius_km = 1.0;
  defaults.spacing_arcsec = 30.0;
  const Lattice l = compute_rf(flat, Transmitter{45.5, 6.5, 10.0, 900.0, std::nullopt, {}, {}}, defaults, itm_options()).path_loss.lattice;
  EXPECT_EQ(l.dims[2], 41);
  EXPECT_EQ(l.world(2, 0), 10.0);
  EXPECT_EQ(l.world(2, 40), 2010.0);
}

TEST(Rf, WritesAVdbThatReadsBackBothGrids) {
  const auto dem = std::filesystem::path(TERRAVOL_SOURCE_DIR) / "data" / "dem" / "N45E006.hgt";
  const io::Mosaic mosaic = io::Mosaic::open({dem});
  RfGrid grid;
  grid.radius_km = 3.0;
  grid.spacing_arcsec = 15.0;
  grid.heights_agl = {0.0, 100.0, 200.0};
  const RfResult r = compute_rf(mosaic, Transmitter{45.5, 6.5, 30.0, 900.0, 50.0, {}, {}}, grid);
  EXPECT_EQ(r.path_loss.attributes.at("dem"), "N45E006.hgt");
  EXPECT_EQ(r.path_loss.attributes.at("tx_lat"), "45.5");
  const std::string bytes = encode_vdb({&r.path_loss, &*r.signal});
  const Volume loss = parse_vdb(bytes, "rf.vdb");
  EXPECT_EQ(loss.name, "path_loss_db");
  EXPECT_EQ(loss.values, r.path_loss.values);
  EXPECT_EQ(loss.lattice, r.path_loss.lattice);
  EXPECT_EQ(loss.frame, r.path_loss.frame);
  EXPECT_EQ(loss.attributes, r.path_loss.attributes);
  ReadOptions o;
  o.field = "signal_dbm";
  const Volume signal = parse_vdb(bytes, "rf.vdb", o);
  EXPECT_EQ(signal.values, r.signal->values);
  EXPECT_EQ(signal.units, "dBm");
}

}  // namespace
}  // namespace terravol::volume
