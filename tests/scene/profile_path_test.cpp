// The profile path's wall (app/scene/profile_path.h) against a profile made up by hand: an
// eastward path over sloping ground, three samples whose clearances give the three colours;
// positions checked back in geodetic coordinates through the frame's exact inverse.
#include "app/scene/profile_path.h"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace terravol::app::scene {
namespace {

constexpr double kLat = 45.5, kLon0 = 6.5, kLon1 = 6.6;

double slope(double, double lon) { return 100.0 + 1000.0 * (lon - kLon0); }

// Three samples along the parallel at 1/4, 1/2 and 3/4 of the way: clear of 60% of F1, inside
// the zone's 60%, and under the terrain's line of sight.
volume::LinkProfile made_up() {
  volume::LinkProfile l;
  l.path.profile.distance_m = 10000.0;
  for (const double t : {0.25, 0.5, 0.75}) {
    l.lat.push_back(kLat);
    l.lon.push_back(kLon0 + t * (kLon1 - kLon0));
    l.fresnel.f1_m.push_back(20.0);
  }
  l.fresnel.clearance_m = {50.0, 5.0, -10.0};
  return l;
}

TEST(ProfilePath, HalfWidthIsFifteenMetresOrAQuarterThousandthOfThePath) {
  EXPECT_DOUBLE_EQ(path_half_width(1000.0), 15.0);
  EXPECT_DOUBLE_EQ(path_half_width(10000.0), 40.0);
}

TEST(ProfilePath, WallFollowsTheGroundAcrossThePathInEachSamplesColour) {
  const io::SceneFrame frame(kLat, 6.55);
  const volume::Mesh m = profile_path_mesh(made_up(), kLat, kLon0, kLat, kLon1, frame, slope);
  // The start, three samples, the end: four vertices each; three quads between neighbours.
  ASSERT_EQ(m.vertices.size(), 20u);
  ASSERT_EQ(m.colors.size(), 20u);
  ASSERT_EQ(m.triangles.size(), 4u * 6u * 3u);
  const double lons[] = {kLon0, 6.525, 6.55, 6.575, kLon1};
  const glm::u8vec4 colors[] = {kPathClear, kPathClear, kPathGrazing, kPathObstructed, kPathObstructed};
  const double w = 40.0;  // path_half_width(10 km)
  for (int s = 0; s < 5; ++s) {
    SCOPED_TRACE(s);
    const double g = slope(kLat, lons[s]);
    const io::ScenePoint centre = frame.to_scene({kLat, lons[s], g});
    // Across an eastward path is north-south: the first two vertices w south of the path, the
    // last two w north; bottom 3 m under the ground, top 2w above it.
    const double dy[] = {-w, -w, w, w}, dh[] = {-3.0, 2.0 * w, 2.0 * w, -3.0};
    for (int k = 0; k < 4; ++k) {
      const glm::dvec3& v = m.vertices[4 * s + k];
      EXPECT_NEAR(v.x, centre.x, 1e-6);
      EXPECT_NEAR(v.y, centre.y + dy[k], 1e-6);
      const io::Geodetic back = frame.to_geodetic({v.x, v.y, v.z});
      // The curvature drop at w beside the path differs from the path's by under 2 cm here.
      EXPECT_NEAR(back.h, g + dh[k], 0.02);
      EXPECT_EQ(m.colors[4 * s + k], colors[s]);
    }
  }
  // Each triangle joins two neighbouring sections and has an area.
  for (std::size_t t = 0; t < m.triangles.size(); t += 3) {
    const std::uint32_t a = m.triangles[t], b = m.triangles[t + 1], c = m.triangles[t + 2];
    const std::uint32_t lo = std::min({a, b, c}) / 4, hi = std::max({a, b, c}) / 4;
    EXPECT_EQ(hi, lo + 1) << t;
    const double area = glm::length(glm::cross(m.vertices[b] - m.vertices[a], m.vertices[c] - m.vertices[a]));
    EXPECT_GT(area, 1.0) << t;
  }
}

TEST(ProfilePath, PathWithoutSamplesIsOneClearSegment) {
  const io::SceneFrame frame(kLat, kLon0);
  volume::LinkProfile l;
  l.path.profile.distance_m = 500.0;
  const volume::Mesh m = profile_path_mesh(l, kLat, kLon0, kLat + 0.004, kLon0, frame, slope);
  ASSERT_EQ(m.vertices.size(), 8u);
  EXPECT_EQ(m.triangle_count(), 6u);
  for (const auto& c : m.colors) EXPECT_EQ(c, kPathClear);
  // Across a northward path is east-west.
  EXPECT_NEAR(m.vertices[0].x - m.vertices[3].x, 30.0, 1e-6);
}

TEST(ProfilePath, EndsAtOnePointThrow) {
  const io::SceneFrame frame(kLat, kLon0);
  EXPECT_THROW(profile_path_mesh(made_up(), kLat, kLon0, kLat, kLon0, frame, slope), std::invalid_argument);
}

}  // namespace
}  // namespace terravol::app::scene
