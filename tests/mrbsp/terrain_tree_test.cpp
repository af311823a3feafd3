#include "mrbsp/terrain_tree.h"

#include "tree_test_util.h"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <set>

namespace terravol::mrbsp {
namespace {

using test::order_violations;
using test::SlidingTerrain;
using test::TestWindow;

Camera looking_down_from(double x, double y, double z) {
  Camera c;
  c.eye = {x, y, z};
  c.forward = {0.0, 0.0, -1.0};
  c.up = {0.0, 1.0, 0.0};
  return c;
}

TEST(TerrainTree, FullResolutionOfAFlatGridIsTwoTrianglesPerCellWithoutCrackFills) {
  const TestWindow w(4, [](int, int) { return 10.0f; });
  const TerrainTree tree(w.view(), 3);
  Frame f;
  TraversalOptions o;
  o.full_res = true;
  o.cull = false;
  tree.traverse(looking_down_from(200, 200, 1000), o, f);
  EXPECT_EQ(f.indices.size(), 4u * 4u * 2u * 3u);
  EXPECT_EQ(f.crack_triangles, 0u);
  EXPECT_EQ(f.leaves, 16u);
  EXPECT_EQ(f.lod_histogram, (std::vector<std::size_t>{0, 0, 16}));
}

TEST(TerrainTree, FlatTerrainNeedsOnlyTheCoarsestLevelUnderTheErrorMetric) {
  const TestWindow w(8, [](int, int) { return 5.0f; });
  const TerrainTree tree(w.view(), 3);  // level 0: 2 x 2 cells of 4 fine cells
  Frame f;
  TraversalOptions o;
  o.cull = false;
  tree.traverse(looking_down_from(400, 400, 50), o, f);
  EXPECT_EQ(f.leaves, 4u);
  EXPECT_EQ(f.indices.size(), 4u * 2u * 3u);
  // The root (a top cell) and its four level-0 cells.
  EXPECT_EQ(f.nodes_visited, 5u);
}

TEST(TerrainTree, PositionsAreTheLatticeSamples) {
  const TestWindow w(4, [](int i, int j) { return static_cast<float>(i * 10 + j); });
  const TerrainTree tree(w.view(), 2);
  const auto& p = tree.positions();
  ASSERT_EQ(p.size(), 25u);
  EXPECT_EQ(tree.merged_base(), 25u);
  EXPECT_EQ(p[7], glm::vec3(200.0f, 100.0f, 21.0f));
}

TEST(TerrainTree, RegionsBehindTheCameraAreCulled) {
  const TestWindow w(16, [](int i, int j) { return static_cast<float>((i * 7 + j * 3) % 11); });
  const TerrainTree tree(w.view(), 4);
  Frame f;
  TraversalOptions o;
  o.full_res = true;
  Camera c = looking_down_from(800, 800, 500);
  c.forward = {0.0, 0.0, 1.0};  // looking at the sky
  tree.traverse(c, o, f);
  EXPECT_TRUE(f.indices.empty());
  c = looking_down_from(800, 800, 500);
  c.fov_y_deg = 10.0;  // sees about 90 m around (800, 800)
  tree.traverse(c, o, f);
  EXPECT_GT(f.leaves, 0u);
  EXPECT_LT(f.leaves, 16u * 16u / 4u);
}

// No allocation per frame: once a Frame has seen a view, traversing it again (and nearby views
// needing no more room) reuses every buffer.
TEST(TerrainTree, WarmTraversalReusesTheFramesBuffers) {
  const TestWindow w(32, [](int i, int j) { return static_cast<float>((i * 37 + j * 11) % 80); });
  const TerrainTree tree(w.view(), 5);
  Camera c = looking_down_from(1600, -800, 500);
  c.forward = glm::normalize(glm::dvec3(0, 1, -0.3));
  c.up = glm::normalize(glm::cross(glm::cross(c.forward, glm::dvec3(0, 0, 1)), c.forward));
  Frame f;
  TraversalOptions o;
  tree.traverse(c, o, f);
  f.indices.reserve(f.indices.size() * 2);
  f.level.reserve(f.level.size() * 2);
  const auto* indices = f.indices.data();
  const auto* level = f.level.data();
  const auto* stack = f.stack_.data();
  const auto* leaves = f.leaves_.data();
  const auto* stamp = f.stamp_.data();
  for (int k = 0; k < 10; ++k) {
    c.eye.x += 10.0;
    tree.traverse(c, o, f);
    ASSERT_GT(f.indices.size(), 0u);
    EXPECT_EQ(f.indices.data(), indices);
    EXPECT_EQ(f.level.data(), level);
    EXPECT_EQ(f.stack_.data(), stack);
    EXPECT_EQ(f.leaves_.data(), leaves);
    EXPECT_EQ(f.stamp_.data(), stamp);
  }
}

TEST(TerrainTree, CrackFillsCanBeLeftOut) {
  const TestWindow w(16, [](int i, int j) { return static_cast<float>((i * 37 + j * 11) % 50); });
  const TerrainTree tree(w.view(), 4);
  Camera c = looking_down_from(800, -600, 300);
  c.forward = glm::normalize(glm::dvec3(0, 1, -0.3));
  c.up = glm::normalize(glm::cross(glm::cross(c.forward, glm::dvec3(0, 0, 1)), c.forward));
  TraversalOptions o;
  o.threshold_px = 20.0f;
  Frame with, without;
  tree.traverse(c, o, with);
  o.crack_fills = false;
  tree.traverse(c, o, without);
  ASSERT_GT(with.crack_triangles, 0u);
  EXPECT_EQ(without.crack_triangles, 0u);
  EXPECT_EQ(std::count(without.level.begin(), without.level.end(), kCrackLevel), 0);
  EXPECT_EQ(static_cast<std::size_t>(std::count(with.level.begin(), with.level.end(), kCrackLevel)), with.crack_triangles);
}

// Balance and crack fills make the drawn terrain watertight: every edge of a drawn triangle
// (crack fills included) inside the window is shared by exactly two drawn triangles, whatever
// the thresholds and eyes, and no two drawn neighbours differ by more than one level.
TEST(TerrainTree, DrawnTerrainIsWatertightAndNeighboursDifferByAtMostOneLevel) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<float> h(0.0f, 300.0f);
  std::vector<float> heights(65 * 65);
  for (float& v : heights) v = h(rng);
  const TestWindow w(64, [&](int i, int j) { return heights[static_cast<std::size_t>(j * 65 + i)]; });
  const TerrainTree tree(w.view(), 6);
  std::uniform_real_distribution<double> xy(-1000.0, 7400.0), z(350.0, 3000.0);
  std::size_t fills = 0, balanced = 0;
  for (int trial = 0; trial < 30; ++trial) {
    Camera c;
    c.eye = {xy(rng), xy(rng), z(rng)};
    TraversalOptions o;
    o.cull = false;
    o.threshold_px = 0.5f * static_cast<float>(1 << (trial % 6));
    o.metric = trial % 3 == 2 ? LodMetric::kArea : LodMetric::kError;
    if (o.metric == LodMetric::kArea) o.threshold_px *= 400.0f;
    Frame f;
    tree.traverse(c, o, f);
    fills += f.crack_triangles;
    balanced += f.balanced_cells;
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> uses;
    for (std::size_t t = 0; t < f.level.size(); ++t) {
      for (int k = 0; k < 3; ++k) {
        std::uint32_t a = f.indices[3 * t + k], b = f.indices[3 * t + (k + 1) % 3];
        if (a > b) std::swap(a, b);
        ++uses[{a, b}];
      }
    }
    const auto on_border = [&](std::uint32_t v) {
      const std::uint32_t i = v % 65, j = v / 65;
      return i == 0 || j == 0 || i == 64 || j == 64;
    };
    int open = 0;
    for (const auto& [edge, count] : uses) {
      const bool border = on_border(edge.first) && on_border(edge.second) &&
                          (edge.first % 65 == edge.second % 65 || edge.first / 65 == edge.second / 65);
      if (count != (border ? 1 : 2)) ++open;
    }
    EXPECT_EQ(open, 0) << "trial " << trial;
  }
  EXPECT_GT(fills, 0u);
  EXPECT_GT(balanced, 0u) << "the test must reach cases balance changes";
}

TEST(TerrainTree, RejectsBadWindowsAndLevels) {
  const TestWindow w(8, [](int, int) { return 0.0f; });
  EXPECT_THROW(TerrainTree(w.view(), 0), std::invalid_argument);
  EXPECT_THROW(TerrainTree(w.view(), 5), std::invalid_argument);
  TestWindow bad(6, [](int, int) { return 0.0f; });
  EXPECT_THROW(TerrainTree(bad.view(), 2), std::invalid_argument);
  TestWindow descending(8, [](int, int) { return 0.0f; });
  descending.xs[3] = descending.xs[2];
  EXPECT_THROW(TerrainTree(descending.view(), 2), std::invalid_argument);
}

TEST(TerrainTree, SlidingGivesTheSameFramesAsBuildingAnew) {
  const SlidingTerrain terrain(99);
  const TestWindow a = terrain.window_at(0, 0), b = terrain.window_at(8, 4);
  TerrainTree slid(a.view(), 4);
  slid.slide(b.view());
  const TerrainTree fresh(b.view(), 4);
  EXPECT_EQ(slid.positions(), fresh.positions());
  Frame fs, ff;
  TraversalOptions o;
  o.threshold_px = 2.0f;
  Camera c = looking_down_from(1500, 900, 800);
  c.forward = glm::normalize(glm::dvec3(0.3, 0.8, -0.5));
  c.up = glm::normalize(glm::cross(glm::cross(c.forward, glm::dvec3(0, 0, 1)), c.forward));
  slid.traverse(c, o, fs);
  fresh.traverse(c, o, ff);
  EXPECT_EQ(fs.indices, ff.indices);
  EXPECT_GT(fs.indices.size(), 0u);
}

TEST(TerrainTree, EmittedOrderIsBackToFrontFromRandomEyes) {
  std::mt19937 rng(2024);
  std::uniform_real_distribution<float> h(0.0f, 40.0f);
  std::vector<float> heights(17 * 17);
  for (std::size_t k = 0; k < heights.size(); ++k)
    heights[k] = 200.0f + 150.0f * std::sin(0.4f * (k % 17)) * std::cos(0.3f * (k / 17)) + h(rng);
  const TestWindow w(16, [&](int i, int j) { return heights[static_cast<std::size_t>(j * 17 + i)]; });
  const TerrainTree tree(w.view(), 4);
  std::uniform_real_distribution<double> xy(-300.0, 1900.0), z(-200.0, 900.0);
  Frame f;
  std::size_t fills = 0, mixed_levels = 0;
  for (int trial = 0; trial < 60; ++trial) {
    glm::dvec3 eye(xy(rng), xy(rng), z(rng));
    if (trial % 4 == 0) eye.x = 800.0;  // exactly on the root's split plane
    if (trial % 4 == 1) eye.y = 400.0;  // on a second-level split plane
    if (trial % 4 == 2) eye.z = 200.0;  // level with much of the terrain
    Camera c;
    c.eye = eye;
    TraversalOptions o;
    o.cull = false;
    o.threshold_px = 2.0f * static_cast<float>(1 << (trial % 7));
    o.front_to_back = trial % 5 == 4;
    tree.traverse(c, o, f);
    fills += f.crack_triangles;
    mixed_levels += std::count_if(f.lod_histogram.begin(), f.lod_histogram.end(), [](std::size_t k) { return k > 0; }) > 1;
    EXPECT_EQ(order_violations(tree, f, eye, 300, rng, !o.front_to_back), 0) << "trial " << trial << " eye " << eye.x
                                                                             << "," << eye.y << "," << eye.z;
  }
  EXPECT_GT(fills, 0u) << "the property must be exercised with crack fills";
  EXPECT_GT(mixed_levels, 30u) << "and with neighbours at different levels";
}

// --- LOD behaviour ---------------------------------------------------------------------------

TEST(TerrainTree, FinerThresholdNeverDrawsFewerLeaves) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> h(0.0f, 200.0f);
  std::vector<float> heights(33 * 33);
  for (float& v : heights) v = h(rng);
  const TestWindow w(32, [&](int i, int j) { return heights[static_cast<std::size_t>(j * 33 + i)]; });
  const TerrainTree tree(w.view(), 5);
  Camera c = looking_down_from(1600, -500, 600);
  c.forward = glm::normalize(glm::dvec3(0, 1, -0.4));
  c.up = glm::normalize(glm::cross(glm::cross(c.forward, glm::dvec3(0, 0, 1)), c.forward));
  for (LodMetric metric : {LodMetric::kError, LodMetric::kArea}) {
    std::size_t previous = 0;
    for (float t : {1000.0f, 100.0f, 10.0f, 1.0f, 0.1f}) {
      Frame f;
      TraversalOptions o;
      o.metric = metric;
      o.threshold_px = metric == LodMetric::kArea ? t * 100.0f : t;
      tree.traverse(c, o, f);
      EXPECT_GE(f.leaves, previous);
      previous = f.leaves;
    }
    Frame full;
    TraversalOptions o;
    o.full_res = true;
    tree.traverse(c, o, full);
    EXPECT_GE(full.leaves, previous);
  }
}

TEST(TerrainTree, CloserRegionsAreDrawnFiner) {
  std::mt19937 rng(8);
  std::uniform_real_distribution<float> h(0.0f, 5.0f);
  std::vector<float> heights(65 * 65);
  for (std::size_t k = 0; k < heights.size(); ++k)
    heights[k] = 100.0f * std::sin(0.2f * (k % 65)) * std::cos(0.15f * (k / 65)) + h(rng);
  const TestWindow w(64, [&](int i, int j) { return heights[static_cast<std::size_t>(j * 65 + i)]; });
  const TerrainTree tree(w.view(), 6);
  Camera c = looking_down_from(3200, -100, 300);
  c.forward = glm::normalize(glm::dvec3(0, 1, -0.3));
  c.up = glm::normalize(glm::cross(glm::cross(c.forward, glm::dvec3(0, 0, 1)), c.forward));
  Frame f;
  TraversalOptions o;
  o.threshold_px = 2.0f;
  tree.traverse(c, o, f);
  // The first triangles drawn are the farthest: coarser on average than the last ones.
  const std::size_t n = f.level.size();
  double first = 0, last = 0;
  int nf = 0, nl = 0;
  for (std::size_t t = 0; t < n / 4; ++t)
    if (f.level[t] >= 0) first += f.level[t], ++nf;
  for (std::size_t t = n - n / 4; t < n; ++t)
    if (f.level[t] >= 0) last += f.level[t], ++nl;
  ASSERT_GT(nf, 0);
  ASSERT_GT(nl, 0);
  EXPECT_LT(first / nf, last / nl);
}

}  // namespace
}  // namespace terravol::mrbsp
