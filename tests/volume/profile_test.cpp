// Link profiles: a single knife edge worked out by hand, the same edge as a ridge in a DEM, and
// the verdicts.
#include "volume/profile.h"

#include <GeographicLib/Geodesic.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "volume_test_util.h"

namespace terravol::volume {
namespace {

// By hand: D = 10 km at 900 MHz (lambda = 0.333103 m), antennas' tops 30 m and 10 m, flat
// ground at 0 m sampled every 100 m but for one 60 m knife edge 4 km from the transmitter.
// At the edge, with k = 4/3:
//   bulge      = 4000 * 6000 / (2 * 4/3 * 6371000)       =   1.4127 m
//   sight line = 30 + (10 - 30) * 4000 / 10000            =  22.0000 m
//   clearance  = 22 - (60 + 1.4127)                       = -39.4127 m
//   F1         = sqrt(0.333103 * 4000 * 6000 / 10000)     =  28.2745 m
//   in F1      = -39.4127 / 28.2745                       =  -1.3939
//   v          = -sqrt(2) * (-1.3939)                     =   1.9713; J(v) = 18.93 dB
PathProfile knife_edge_path() {
  PathProfile p;
  p.distance_m = 10000.0;
  p.tx_height_m = 30.0;
  p.rx_height_m = 10.0;
  for (int d = 100; d < 10000; d += 100) {
    p.d_m.push_back(d);
    p.z_m.push_back(d == 4000 ? 60.0 : 0.0);
  }
  return p;
}

TEST(Fresnel, SingleKnifeEdgeAsWorkedOutByHand) {
  const PathProfile p = knife_edge_path();
  const FresnelAnalysis f = analyse_fresnel(p, 900.0, 4.0 / 3.0);
  ASSERT_EQ(f.worst, 39u);  // d = 4000 m
  EXPECT_NEAR(f.bulge_m[39], 1.4127, 1e-3);
  EXPECT_NEAR(f.los_m[39], 22.0, 1e-9);
  EXPECT_NEAR(f.f1_m[39], 28.2745, 1e-3);
  EXPECT_NEAR(f.worst_clearance_m, -39.4127, 0.1);  // the target: 0.1 m
  EXPECT_NEAR(f.worst_clearance_m, -39.4127, 1e-3);
  EXPECT_NEAR(f.worst_clearance_f1, -1.3939, 1e-3);
  EXPECT_FALSE(f.line_of_sight);
  EXPECT_FALSE(f.fresnel_60);
  EXPECT_DOUBLE_EQ(f.clearance_m[38], 30.0 - 20.0 * 3900.0 / 10000.0 - 3900.0 * 6100.0 / (2.0 * 4.0 / 3.0 * 6371000.0));
  // The model's knife-edge loss on the same profile: one edge, J(1.9713).
  EXPECT_NEAR(diffraction_loss_db(p, 900.0), knife_edge_loss_db(1.9713), 0.01);
  EXPECT_NEAR(diffraction_loss_db(p, 900.0), 18.93, 0.01);
}

TEST(Fresnel, VerdictsFollowTheClearance) {
  PathProfile p = knife_edge_path();
  // Flat ground under 40 m masts: at least 38.5 m below a line whose F1 is at most 28.9 m.
  p.z_m[39] = 0.0;
  p.tx_height_m = p.rx_height_m = 40.0;
  FresnelAnalysis f = analyse_fresnel(p, 900.0, 4.0 / 3.0);
  EXPECT_TRUE(f.line_of_sight);
  EXPECT_TRUE(f.fresnel_60);
  EXPECT_GT(f.worst_clearance_f1, 1.3);
  // Flat ground under 30 m and 10 m masts: clear sight, but near the low end less than 0.6 F1.
  p.tx_height_m = 30.0;
  p.rx_height_m = 10.0;
  f = analyse_fresnel(p, 900.0, 4.0 / 3.0);
  EXPECT_TRUE(f.line_of_sight);
  EXPECT_FALSE(f.fresnel_60);
  // An edge 10 m below the line of sight at 4 km: clear sight, 10 / 28.27 = 0.35 F1 < 0.6.
  p.z_m[39] = 22.0 - 10.0 - f.bulge_m[39];
  f = analyse_fresnel(p, 900.0, 4.0 / 3.0);
  EXPECT_TRUE(f.line_of_sight);
  EXPECT_FALSE(f.fresnel_60);
  EXPECT_EQ(f.worst, 39u);
  EXPECT_NEAR(f.worst_clearance_m, 10.0, 1e-9);
  EXPECT_NEAR(f.worst_clearance_f1, 10.0 / 28.2745, 1e-4);
  EXPECT_THROW(analyse_fresnel(p, 0.0, 4.0 / 3.0), std::invalid_argument);
}

// A 3" DEM over 45..46 N, 6..7 E, flat at 0 m but for a 60 m north-south ridge, flat-topped over
// four samples from 6.55 E: a path along the parallel 45.5 N crosses it.
io::Grid ridge_dem() {
  return test::synthetic_dem([](double, double lon) {
    const int c = static_cast<int>(std::lround((lon - 6.0) * 1200.0));
    return c >= 660 && c <= 663 ? 60.0 : 0.0;
  });
}

TEST(LinkProfile, RidgeInADemIsTheKnifeEdgeByHand) {
  const io::Grid dem = ridge_dem();
  Transmitter tx;
  tx.lat = 45.5;
  tx.lon = 6.5;
  tx.height_agl = 30.0;
  const double rx_lat = 45.5, rx_lon = 6.625;
  const LinkProfile l = link_profile(dem, tx, rx_lat, rx_lon, 10.0);
  double D = 0.0;
  GeographicLib::Geodesic::WGS84().Inverse(tx.lat, tx.lon, rx_lat, rx_lon, D);
  EXPECT_NEAR(l.path.profile.distance_m, D, 1e-6);
  const std::size_t w = l.fresnel.worst;
  ASSERT_LT(w, l.lat.size());
  // The worst sample lies on the ridge's flat top, so the ground there is 60 m exactly.
  EXPECT_GE(l.lon[w], 6.55);
  EXPECT_LE(l.lon[w], 6.5525);
  EXPECT_NEAR(l.path.profile.z_m[w], 60.0, 1e-9);
  // By hand at its distance d.
  const double d = l.path.profile.d_m[w];
  const double bulge = d * (D - d) / (2.0 * 4.0 / 3.0 * 6371000.0);
  const double los = 30.0 + (10.0 - 30.0) * d / D;
  const double f1 = std::sqrt(299792458.0 / 900e6 * d * (D - d) / D);
  EXPECT_NEAR(l.fresnel.worst_clearance_m, los - 60.0 - bulge, 0.1);
  EXPECT_NEAR(l.fresnel.worst_clearance_f1, (los - 60.0 - bulge) / f1, 1e-3);
  // It is the worst of the ridge's samples, and the model's only edge.
  for (std::size_t i = 0; i < l.lat.size(); ++i) {
    if (l.lon[i] < 6.55 || l.lon[i] > 6.5525) continue;
    const double di = l.path.profile.d_m[i];
    const double ci = 30.0 + (10.0 - 30.0) * di / D - 60.0 - di * (D - di) / (2.0 * 4.0 / 3.0 * 6371000.0);
    EXPECT_GE(ci / std::sqrt(299792458.0 / 900e6 * di * (D - di) / D), l.fresnel.worst_clearance_f1 - 1e-12);
  }
  ASSERT_EQ(l.path.edges.size(), 1u);
  EXPECT_GE(l.lon[l.path.edges[0].sample], 6.55);
  EXPECT_LE(l.lon[l.path.edges[0].sample], 6.5525);
  EXPECT_NEAR(l.path.diffraction_db, knife_edge_loss_db(l.path.edges[0].v), 1e-12);
  EXPECT_NEAR(l.tx_ground_m, 0.0, 1e-12);
  EXPECT_NE(verdict(l).find("obstructed: terrain "), std::string::npos) << verdict(l);
  EXPECT_NE(verdict(l).find("over 1 edge)"), std::string::npos) << verdict(l);
}

}  // namespace
}  // namespace terravol::volume
