#include "io/void_fill.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

namespace terravol::io {
namespace {

Grid plane(int rows, int cols) {
  Grid g;
  g.allocate(rows, cols);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) g.heights[g.index(r, c)] = 100.0f + 2.0f * r - 3.0f * c;
  return g;
}

TEST(FillVoids, SingleVoidInAPlaneGetsThePlanesHeight) {
  Grid g = plane(8, 8);
  g.mask[g.index(3, 4)] = Sample::kVoid;
  g.heights[g.index(3, 4)] = 0.0f;
  EXPECT_EQ(fill_voids(g), 1u);
  EXPECT_FLOAT_EQ(g.heights[g.index(3, 4)], 100.0f + 6.0f - 12.0f);
  EXPECT_EQ(g.mask[g.index(3, 4)], Sample::kVoid) << "the mask still tells where the void was";
}

TEST(FillVoids, LargeHoleInAPlaneConvergesToThePlane) {
  Grid g = plane(40, 40);
  for (int r = 10; r < 22; ++r)
    for (int c = 15; c < 27; ++c) {
      g.mask[g.index(r, c)] = Sample::kVoid;
      g.heights[g.index(r, c)] = 0.0f;
    }
  EXPECT_EQ(fill_voids(g, 400), 144u);
  for (int r = 10; r < 22; ++r)
    for (int c = 15; c < 27; ++c) EXPECT_NEAR(g.heights[g.index(r, c)], 100.0f + 2.0f * r - 3.0f * c, 0.05);
}

// Property: filled heights never leave the range of the valid heights (maximum principle).
TEST(FillVoids, FilledHeightsStayWithinTheValidRange) {
  std::mt19937 rng(1234);
  std::uniform_real_distribution<float> height(-50.0f, 3000.0f);
  std::bernoulli_distribution hole(0.3);
  for (int trial = 0; trial < 20; ++trial) {
    Grid g;
    g.allocate(17 + trial, 23);
    for (std::size_t i = 0; i < g.size(); ++i) {
      g.heights[i] = height(rng);
      if (hole(rng)) g.mask[i] = trial % 2 ? Sample::kVoid : Sample::kOutside;
    }
    const auto range = height_range(g);
    const std::size_t voids = g.size() - count(g, Sample::kValid);
    EXPECT_EQ(fill_voids(g), voids);
    for (float h : g.heights) {
      EXPECT_GE(h, range.min);
      EXPECT_LE(h, range.max);
    }
  }
}

TEST(FillVoids, AllVoidGridBecomesSeaLevel) {
  Grid g;
  g.allocate(3, 4);
  std::fill(g.mask.begin(), g.mask.end(), Sample::kVoid);
  EXPECT_EQ(fill_voids(g), 12u);
  for (float h : g.heights) EXPECT_EQ(h, 0.0f);
}

TEST(FillVoids, GridWithoutVoidsIsUntouched) {
  Grid g = plane(5, 5);
  const auto before = g.heights;
  EXPECT_EQ(fill_voids(g), 0u);
  EXPECT_EQ(g.heights, before);
}

}  // namespace
}  // namespace terravol::io
