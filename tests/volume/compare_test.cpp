// volume/compare.h: trilinear resampling (exact on linear fields, NaN and bounds honoured) and
// the per-layer statistics on cases with known answers.
#include "volume/compare.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

namespace terravol::volume {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// f(w) = 2 w0 - 3 w1 + 0.5 w2 + 7 on a geographic lattice (heights above ground).
Volume linear_volume(std::array<int, 3> dims, std::array<double, 3> origin,
                     std::array<double, 3> spacing) {
  Volume v;
  v.name = "path_loss_db";
  v.frame = parse_frame("geographic-agl");
  v.lattice.dims = dims;
  v.lattice.origin = origin;
  v.lattice.spacing = spacing;
  v.values.resize(v.lattice.size());
  for (int k = 0; k < dims[2]; ++k)
    for (int j = 0; j < dims[1]; ++j)
      for (int i = 0; i < dims[0]; ++i) {
        const Lattice& l = v.lattice;
        v.values[l.index(i, j, k)] = static_cast<float>(2.0 * l.world(0, i) - 3.0 * l.world(1, j) +
                                                        0.5 * l.world(2, k) + 7.0);
      }
  return v;
}

TEST(CompareTrilinear, ReproducesALinearFieldAtRandomPoints) {
  const Volume v = linear_volume({5, 4, 3}, {-111.9, 40.7, 10.0}, {0.01, 0.02, 50.0});
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int n = 0; n < 500; ++n) {
    const double w0 = -111.9 + 0.04 * u(rng), w1 = 40.7 + 0.06 * u(rng), w2 = 10.0 + 100.0 * u(rng);
    const auto x = sample_trilinear(v, w0, w1, w2);
    ASSERT_TRUE(x.has_value());
    EXPECT_NEAR(*x, 2.0 * w0 - 3.0 * w1 + 0.5 * w2 + 7.0, 1e-3);
  }
}

TEST(CompareTrilinear, OutsideTheLatticeIsNothing) {
  const Volume v = linear_volume({3, 3, 2}, {0.0, 0.0, 0.0}, {1.0, 1.0, 10.0});
  EXPECT_FALSE(sample_trilinear(v, -0.01, 1.0, 5.0));
  EXPECT_FALSE(sample_trilinear(v, 1.0, 2.01, 5.0));
  EXPECT_FALSE(sample_trilinear(v, 1.0, 1.0, 10.5));
  EXPECT_TRUE(sample_trilinear(v, 2.0, 2.0, 10.0));  // the far corner itself
  EXPECT_FALSE(sample_trilinear(v, std::nan(""), 1.0, 1.0));
}

TEST(CompareTrilinear, NaNCornersWithWeightPoisonOnlyTheirCells) {
  Volume v = linear_volume({3, 2, 1}, {0.0, 0.0, 0.0}, {1.0, 1.0, 1.0});
  v.values[v.lattice.index(2, 0, 0)] = kNaN;
  EXPECT_FALSE(sample_trilinear(v, 1.5, 0.5, 0.0));          // a cell touching the NaN point
  EXPECT_TRUE(sample_trilinear(v, 0.5, 0.5, 0.0));           // its neighbour does not
  const auto on_point = sample_trilinear(v, 1.0, 0.0, 0.0);  // the NaN point has zero weight
  ASSERT_TRUE(on_point);
  EXPECT_NEAR(*on_point, 2.0 + 7.0, 1e-6);
}

TEST(CompareTrilinear, ASingleLayerMatchesOnlyItsOwnHeight) {
  const Volume v = linear_volume({2, 2, 1}, {0.0, 0.0, 100.0}, {1.0, 1.0, 1.0});
  EXPECT_TRUE(sample_trilinear(v, 0.5, 0.5, 100.0));
  EXPECT_FALSE(sample_trilinear(v, 0.5, 0.5, 100.5));
}

TEST(CompareVolumes, IdenticalVolumesCorrelatePerfectly) {
  const Volume a = linear_volume({6, 5, 3}, {0.0, 0.0, 10.0}, {1.0, 1.0, 50.0});
  const Comparison c = compare_volumes(a, a);
  ASSERT_EQ(c.layers.size(), 3u);
  for (const auto& layer : c.layers) {
    EXPECT_EQ(layer.points, 30u);
    EXPECT_NEAR(layer.pearson, 1.0, 1e-12);
    EXPECT_EQ(layer.median_difference, 0.0);
    EXPECT_EQ(layer.median_abs_difference, 0.0);
  }
  EXPECT_DOUBLE_EQ(c.layers[1].w2, 60.0);
  EXPECT_EQ(c.all.points, 90u);
  EXPECT_TRUE(std::isnan(c.all.w2));
}

TEST(CompareVolumes, KnownOffsetsSignsAndMedians) {
  Volume a;
  a.frame = parse_frame("geographic-agl");
  a.lattice.dims = {4, 1, 1};
  a.values = {1.0f, 2.0f, 3.0f, 4.0f};
  Volume b = a;
  b.values = {4.0f, 5.0f, 7.0f, 6.0f};  // B - A = 3, 3, 4, 2
  const LayerComparison c = compare_volumes(a, b).layers[0];
  EXPECT_EQ(c.points, 4u);
  EXPECT_DOUBLE_EQ(c.median_difference, 3.0);  // mean of the middle two of 2, 3, 3, 4
  EXPECT_DOUBLE_EQ(c.median_abs_difference, 3.0);
  EXPECT_DOUBLE_EQ(c.median_a, 2.5);
  EXPECT_DOUBLE_EQ(c.median_b, 5.5);
  EXPECT_NEAR(c.pearson, 0.8, 1e-12);  // cov 1.0 / sqrt(1.25 * 1.25)
  b.values = {-1.0f, -2.0f, -3.0f, -4.0f};
  EXPECT_NEAR(compare_volumes(a, b).layers[0].pearson, -1.0, 1e-12);
  EXPECT_DOUBLE_EQ(compare_volumes(a, b).layers[0].median_difference, -5.0);
}

TEST(CompareVolumes, SkipsNaNAndPointsOutsideB) {
  Volume a = linear_volume({10, 1, 2}, {0.0, 0.0, 0.0}, {1.0, 1.0, 10.0});
  a.values[a.lattice.index(0, 0, 0)] = kNaN;
  Volume b = linear_volume({6, 1, 2}, {0.0, 0.0, 0.0}, {1.0, 1.0, 10.0});  // covers i = 0..5
  b.values[b.lattice.index(5, 0, 1)] = kNaN;
  const Comparison c = compare_volumes(a, b);
  EXPECT_EQ(c.layers[0].points, 5u);  // i = 1..5
  EXPECT_EQ(c.layers[1].points, 5u);  // i = 0..4
  EXPECT_EQ(c.all.points, 10u);
  EXPECT_EQ(c.all.median_abs_difference, 0.0);
}

TEST(CompareVolumes, AFinerBIsInterpolatedAndACoarserOneToo) {
  const Volume fine = linear_volume({41, 31, 5}, {-112.0, 40.5, 0.0}, {0.005, 0.005, 25.0});
  const Volume coarse = linear_volume({9, 7, 2}, {-111.99, 40.51, 10.0}, {0.02, 0.02, 50.0});
  for (const auto& c : {compare_volumes(coarse, fine), compare_volumes(fine, coarse)}) {
    EXPECT_GT(c.all.points, 50u);
    EXPECT_LT(c.all.median_abs_difference, 1e-4);
    EXPECT_NEAR(c.all.pearson, 1.0, 1e-9);
  }
}

TEST(CompareVolumes, NoPointsGivesNaNStatistics) {
  const Volume a = linear_volume({2, 2, 1}, {0.0, 0.0, 0.0}, {1.0, 1.0, 1.0});
  const Volume b = linear_volume({2, 2, 1}, {5.0, 5.0, 0.0}, {1.0, 1.0, 1.0});
  const Comparison c = compare_volumes(a, b);
  EXPECT_EQ(c.all.points, 0u);
  EXPECT_TRUE(std::isnan(c.all.pearson));
  EXPECT_TRUE(std::isnan(c.all.median_difference));
}

TEST(CompareVolumes, DifferentFramesAreRefused) {
  const Volume a = linear_volume({2, 2, 1}, {0.0, 0.0, 0.0}, {1.0, 1.0, 1.0});
  Volume b = a;
  b.frame = parse_frame("geographic");
  try {
    compare_volumes(a, b);
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "the frames differ: geographic-agl vs geographic");
  }
}

}  // namespace
}  // namespace terravol::volume
