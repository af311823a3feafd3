#include "mrbsp/terrain_tree.h"

#include "tree_test_util.h"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
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

TEST(TerrainTree, PositionsAreTheLatticeSamplesThenTheirWallCopies) {
  const TestWindow w(4, [](int i, int j) { return static_cast<float>(i * 10 + j); });
  const TerrainTree tree(w.view(), 2);
  const auto& p = tree.positions();
  ASSERT_EQ(p.size(), 25u + 8 * 5);
  EXPECT_EQ(tree.merged_base(), 65u);
  EXPECT_EQ(p[7], glm::vec3(200.0f, 100.0f, 21.0f));
  // West side: the copies of samples (0, j), then the same 100 m below the lowest sample (0).
  for (int j = 0; j <= 4; ++j) {
    EXPECT_EQ(p[25 + static_cast<std::size_t>(j)], p[static_cast<std::size_t>(j * 5)]);
    EXPECT_EQ(p[30 + static_cast<std::size_t>(j)], glm::vec3(p[static_cast<std::size_t>(j * 5)].x, p[static_cast<std::size_t>(j * 5)].y, -100.0f));
  }
  // North side (the fourth): samples (i, 4).
  EXPECT_EQ(p[25 + 30 + 3], p[4 * 5 + 3]);
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
// Edges are compared by their end points' positions, so that a wall's top edge (copies of the
// boundary samples) meets the terrain's border edge it hangs from.
TEST(TerrainTree, DrawnTerrainIsWatertightWithWallsOnTheSidesTheEyeIsBeyond) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<float> h(0.0f, 300.0f);
  std::vector<float> heights(65 * 65);
  for (float& v : heights) v = h(rng);
  const TestWindow w(64, [&](int i, int j) { return heights[static_cast<std::size_t>(j * 65 + i)]; });
  const TerrainTree tree(w.view(), 6);
  const auto& p = tree.positions();
  const float x0 = p[0].x, x1 = p[64].x, y0 = p[0].y, y1 = p[64 * 65].y;
  const float base = *std::min_element(heights.begin(), heights.end()) - 100.0f;
  std::uniform_real_distribution<double> xy(-1000.0, 7400.0), z(350.0, 3000.0);
  std::size_t fills = 0, balanced = 0, walled_frames = 0;
  for (int trial = 0; trial < 30; ++trial) {
    Camera c;
    c.eye = {xy(rng), xy(rng), z(rng)};
    const bool beyond[4] = {c.eye.x < x0, c.eye.x > x1, c.eye.y < y0, c.eye.y > y1};
    TraversalOptions o;
    o.cull = false;
    o.threshold_px = 0.5f * static_cast<float>(1 << (trial % 6));
    o.metric = trial % 3 == 2 ? LodMetric::kArea : LodMetric::kError;
    if (o.metric == LodMetric::kArea) o.threshold_px *= 400.0f;
    Frame f;
    tree.traverse(c, o, f);
    fills += f.crack_triangles;
    balanced += f.balanced_cells;
    const bool any_beyond = beyond[0] || beyond[1] || beyond[2] || beyond[3];
    const auto walls = std::count(f.level.begin(), f.level.end(), kWallLevel);
    EXPECT_EQ(walls > 0, any_beyond) << "trial " << trial;
    walled_frames += walls > 0 ? 1 : 0;
    using Key = std::array<float, 3>;
    const auto key = [&](std::uint32_t v) { return Key{p[v].x, p[v].y, p[v].z}; };
    std::map<std::pair<Key, Key>, int> uses;
    for (std::size_t t = 0; t < f.level.size(); ++t) {
      if (f.level[t] == kWallLevel) {
        for (int k = 0; k < 3; ++k) {
          const glm::vec3 q = p[f.indices[3 * t + k]];
          const bool in_a_walled_plane = (beyond[0] && q.x == x0) || (beyond[1] && q.x == x1) || (beyond[2] && q.y == y0) ||
                                         (beyond[3] && q.y == y1);
          EXPECT_TRUE(in_a_walled_plane) << "trial " << trial;
        }
      }
      for (int k = 0; k < 3; ++k) {
        Key a = key(f.indices[3 * t + k]), b = key(f.indices[3 * t + (k + 1) % 3]);
        if (b < a) std::swap(a, b);
        ++uses[{a, b}];
      }
    }
    // Expected uses: 2 inside; a border edge 1, or 2 on a walled side; a wall's bottom edge 1;
    // a wall's vertical edge at a window corner 1, or 2 where two walled sides meet there.
    const auto side_of = [&](const Key& a, const Key& b) {
      if (a[0] == x0 && b[0] == x0) return 0;
      if (a[0] == x1 && b[0] == x1) return 1;
      if (a[1] == y0 && b[1] == y0) return 2;
      if (a[1] == y1 && b[1] == y1) return 3;
      return -1;
    };
    int open = 0;
    for (const auto& [edge, count] : uses) {
      const auto& [a, b] = edge;
      int expected = 2;
      const bool vertical = a[0] == b[0] && a[1] == b[1];
      const bool corner = (a[0] == x0 || a[0] == x1) && (a[1] == y0 || a[1] == y1);
      if (a[2] == base && b[2] == base) {
        expected = 1;
      } else if (vertical && corner) {
        expected = (beyond[a[0] == x0 ? 0 : 1] ? 1 : 0) + (beyond[a[1] == y0 ? 2 : 3] ? 1 : 0);
      } else if (!vertical && side_of(a, b) >= 0 && a[2] != base && b[2] != base) {
        expected = beyond[side_of(a, b)] ? 2 : 1;
      }
      if (count != expected) ++open;
    }
    EXPECT_EQ(open, 0) << "trial " << trial;
  }
  EXPECT_GT(fills, 0u);
  EXPECT_GT(balanced, 0u) << "the test must reach cases balance changes";
  EXPECT_GT(walled_frames, 5u) << "the test must reach eyes beyond the window";
  EXPECT_LT(walled_frames, 30u) << "and eyes above it";
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
