// app/scene/terrain_colors.h: tint, hillshade, water, LOD colours and the sky.
#include <gtest/gtest.h>

#include <vector>

#include "app/scene/terrain_colors.h"

namespace terravol::app::scene {
namespace {

struct Lattice {
  int cells;
  std::vector<double> xs, ys;
  std::vector<float> z, h;
};

// A 4 x 4-cell lattice with 100 m spacing; heights from f(x, y).
template <typename F>
Lattice lattice(F f) {
  Lattice l{4, {}, {}, {}, {}};
  for (int i = 0; i <= 4; ++i) {
    l.xs.push_back(100.0 * i);
    l.ys.push_back(100.0 * i);
  }
  for (int j = 0; j <= 4; ++j)
    for (int i = 0; i <= 4; ++i) {
      l.h.push_back(f(l.xs[i], l.ys[j]));
      l.z.push_back(l.h.back());
    }
  return l;
}

TerrainShading shade(const Lattice& l, ShadingOptions o = {}) { return shade_terrain(l.cells, l.xs, l.ys, l.z, l.h, o); }

// On a tilted plane z = a x + b y every sample's normal, central or one-sided, is the plane's,
// on lattices of uneven spacing too.
TEST(TerrainColors, LatticeNormalsOfAPlaneAreThePlanes) {
  const std::vector<double> xs{0.0, 10.0, 25.0, 31.0, 60.0}, ys{-5.0, 0.0, 30.0, 35.0, 90.0};
  const double a = 0.3, b = -1.7;
  const glm::dvec3 expected = glm::normalize(glm::dvec3(-a, -b, 1.0));
  for (int j = 0; j <= 4; ++j) {
    for (int i = 0; i <= 4; ++i) {
      const glm::dvec3 n = lattice_normal(
          4, i, j, [&](int ii) { return xs[static_cast<std::size_t>(ii)]; }, [&](int jj) { return ys[static_cast<std::size_t>(jj)]; },
          [&](int ii, int jj) { return a * xs[static_cast<std::size_t>(ii)] + b * ys[static_cast<std::size_t>(jj)]; });
      EXPECT_NEAR(glm::length(n - expected), 0.0, 1e-12) << i << ", " << j;
    }
  }
}

TEST(TerrainColors, FlatLandKeepsItsTintAndWaterIsBlue) {
  const auto flat = shade(lattice([](double, double) { return 500.0f; }));
  ASSERT_EQ(flat.rgba.size(), 25u);
  EXPECT_FLOAT_EQ(flat.shade[12], 1.0f);
  EXPECT_EQ(flat.rgba[12], tint_of(500.0f, Tint::kAtlas, 0, 0));
  const auto sea = shade(lattice([](double, double) { return 0.0f; }));
  EXPECT_GT(sea.rgba[12][2], sea.rgba[12][0]) << "water is blue";
  EXPECT_GT(sea.rgba[12][2], sea.rgba[12][1]);
}

TEST(TerrainColors, SlopesFacingTheSunAreBrighterThanSlopesFacingAway) {
  // Ground rising to the east: its normal leans west. A sun in the west lights it.
  const auto l = lattice([](double x, double) { return 500.0f + 0.5f * static_cast<float>(x); });
  ShadingOptions west;
  west.sun_azimuth_deg = 270.0;
  ShadingOptions east;
  east.sun_azimuth_deg = 90.0;
  EXPECT_GT(shade(l, west).shade[12], 1.0f);
  EXPECT_LT(shade(l, east).shade[12], 1.0f);
  EXPECT_GE(shade(l, east).shade[12], static_cast<float>(east.ambient) - 1e-6f);
}

TEST(TerrainColors, WallVerticesTakeTheWallColourAndNoTexture) {
  const auto l = lattice([](double x, double y) { return static_cast<float>(x + 2 * y); });
  const auto s = shade(l);
  const std::vector<glm::u8vec4> merged{{1, 2, 3, 128}};
  const auto v = vertex_shading(s, 25 + 40, merged);  // a 4-cell window's lattice and walls
  ASSERT_EQ(v.rgba.size(), 25u + 40 + 1);
  for (std::size_t k = 0; k < 25; ++k) EXPECT_EQ(v.rgba[k], s.rgba[k]);
  for (std::size_t k = 25; k < 65; ++k) {
    EXPECT_EQ(v.rgba[k], kWallColor);
    EXPECT_LT(v.tcoords[k].x, 0.0f) << "the renderer draws the wall's own colour";
  }
  EXPECT_EQ(v.rgba.back(), (Rgba{1, 2, 3, 128}));
}

// The renderer appends lazily built merged vertices to the shade and colours it keeps: they
// come with the room the renderer keeps, so that those appends do not move them.
TEST(TerrainColors, VertexShadingLeavesTheRenderersRoomForMoreVertices) {
  const auto s = shade(lattice([](double x, double) { return static_cast<float>(x); }));
  const std::vector<glm::u8vec4> merged(300, glm::u8vec4{9, 9, 9, 200});
  const auto v = vertex_shading(s, 25, merged);
  const std::size_t total = 25 + 300;
  ASSERT_EQ(v.rgba.size(), total);
  ASSERT_EQ(v.shade.size(), total);
  EXPECT_GE(v.rgba.capacity(), total + total / kVertexRoom);
  EXPECT_GE(v.shade.capacity(), total + total / kVertexRoom);
}

TEST(TerrainColors, LodColoursAreDistinctAndNeverMagenta) {
  for (int a = 0; a < 10; ++a) {
    EXPECT_GT(lod_color(a)[1], 60);
    for (int b = a + 1; b < 10; ++b) EXPECT_NE(lod_color(a), lod_color(b));
  }
  EXPECT_EQ(lod_color(-1), kCrackColor);
}

TEST(TerrainColors, SkyIsHazeAtTheHorizonAndBluerAbove) {
  const auto level = sky_gradient(0.0, 40.0);  // horizon in the middle of the image
  EXPECT_LT(level[1][0], kHorizon[0]) << "the top is bluer (less red) than the horizon";
  const auto down = sky_gradient(-60.0, 40.0);  // the horizon is above the image
  EXPECT_EQ(down[0], kHorizon);
  EXPECT_EQ(down[1], kHorizon);
}

}  // namespace
}  // namespace terravol::app::scene
