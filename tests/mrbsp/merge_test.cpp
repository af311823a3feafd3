#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "mrbsp/terrain_tree.h"
#include "tree_test_util.h"

namespace terravol::mrbsp {
namespace {

using test::order_violations;
using test::TestWindow;

// Random triangles through the terrain's volume (big and small), plus two lying exactly in
// split planes (the root's x = 800 and a y plane), all translucent.
struct Soup {
  std::vector<glm::dvec3> v;
  std::vector<glm::u8vec4> c;
  std::vector<std::uint32_t> t;
  double area = 0.0;
  void add(glm::dvec3 a, glm::dvec3 b, glm::dvec3 d) {
    const auto base = static_cast<std::uint32_t>(v.size());
    v.insert(v.end(), {a, b, d});
    c.insert(c.end(), 3, glm::u8vec4(200, 100, 50, 120));
    t.insert(t.end(), {base, base + 1, base + 2});
    area += 0.5 * glm::length(glm::cross(b - a, d - a));
  }
};

Soup random_soup(std::mt19937& rng, int count) {
  std::uniform_real_distribution<double> xy(-100.0, 1700.0), z(-50.0, 500.0), small(-150.0, 150.0);
  Soup s;
  for (int k = 0; k < count; ++k) {
    const glm::dvec3 a(xy(rng), xy(rng), z(rng));
    if (k % 2) {
      s.add(a, a + glm::dvec3(small(rng), small(rng), small(rng)), a + glm::dvec3(small(rng), small(rng), small(rng)));
    } else {
      s.add(a, {xy(rng), xy(rng), z(rng)}, {xy(rng), xy(rng), z(rng)});
    }
  }
  s.add({800.0, 100.0, 0.0}, {800.0, 900.0, 50.0}, {800.0, 500.0, 450.0});  // in the root plane
  s.add({300.0, 400.0, 20.0}, {1200.0, 400.0, 30.0}, {700.0, 400.0, 380.0});  // in a y plane
  return s;
}

double drawn_merged_area(const TerrainTree& tree, const Frame& f) {
  double area = 0.0;
  const auto& p = tree.positions();
  for (std::size_t t = 0; t < f.level.size(); ++t) {
    if (f.level[t] != kMergedLevel) continue;
    const glm::dvec3 a(p[f.indices[3 * t]]), b(p[f.indices[3 * t + 1]]), c(p[f.indices[3 * t + 2]]);
    area += 0.5 * glm::length(glm::cross(b - a, c - a));
  }
  return area;
}

TerrainTree hilly_tree(std::mt19937& rng, TestWindow& w) {
  std::uniform_real_distribution<float> h(0.0f, 40.0f);
  for (std::size_t k = 0; k < w.z.size(); ++k)
    w.z[k] = 200.0f + 150.0f * std::sin(0.4f * static_cast<float>(k % 17)) * std::cos(0.3f * static_cast<float>(k / 17)) + h(rng);
  return TerrainTree(w.view(), 4);
}

TEST(Merge, MergedAndTerrainTrianglesAreInBackToFrontOrderFromRandomEyes) {
  std::mt19937 rng(77);
  TestWindow w(16, [](int, int) { return 0.0f; });
  TerrainTree tree = hilly_tree(rng, w);
  const Soup soup = random_soup(rng, 24);
  const MergeStats stats = tree.merge(soup.v, soup.c, soup.t);
  EXPECT_EQ(stats.input_triangles, soup.t.size() / 3);
  EXPECT_GT(stats.stored_polygons, stats.input_triangles) << "spanning triangles are split and copied per LOD";
  std::uniform_real_distribution<double> xy(-300.0, 1900.0), z(-200.0, 900.0);
  Frame f;
  std::size_t merged = 0;
  for (int trial = 0; trial < 40; ++trial) {
    glm::dvec3 eye(xy(rng), xy(rng), z(rng));
    if (trial % 3 == 0) eye.x = 800.0;
    Camera c;
    c.eye = eye;
    TraversalOptions o;
    o.cull = false;
    o.threshold_px = 2.0f * static_cast<float>(1 << (trial % 7));
    o.front_to_back = trial % 5 == 4;
    tree.traverse(c, o, f);
    merged += static_cast<std::size_t>(std::count(f.level.begin(), f.level.end(), kMergedLevel));
    EXPECT_EQ(order_violations(tree, f, eye, 200, rng, !o.front_to_back), 0) << "trial " << trial;
  }
  EXPECT_GT(merged, 0u);
}

// Each part of each merged triangle is drawn exactly once, whatever the LOD choice: copies
// live in every alternative, but one alternative is drawn per region.
TEST(Merge, DrawnMergedAreaEqualsTheInputAreaAtEveryThreshold) {
  std::mt19937 rng(3);
  TestWindow w(16, [](int, int) { return 0.0f; });
  TerrainTree tree = hilly_tree(rng, w);
  const Soup soup = random_soup(rng, 30);
  tree.merge(soup.v, soup.c, soup.t);
  Camera c;
  c.eye = {-400.0, -300.0, 700.0};
  Frame f;
  for (float t : {0.5f, 4.0f, 64.0f, 10000.0f}) {
    TraversalOptions o;
    o.cull = false;
    o.threshold_px = t;
    tree.traverse(c, o, f);
    EXPECT_NEAR(drawn_merged_area(tree, f), soup.area, 1e-6 * soup.area) << "threshold " << t;
  }
  TraversalOptions full;
  full.cull = false;
  full.full_res = true;
  tree.traverse(c, full, f);
  EXPECT_NEAR(drawn_merged_area(tree, f), soup.area, 1e-6 * soup.area);
}

TEST(Merge, SlidingMergesThePolygonsAgainIntoTheMovedWindow) {
  std::mt19937 rng(12);
  TestWindow w(16, [](int, int) { return 0.0f; });
  TerrainTree tree = hilly_tree(rng, w);
  const Soup soup = random_soup(rng, 10);
  tree.merge(soup.v, soup.c, soup.t);
  TestWindow moved(16, [](int i, int j) { return static_cast<float>(i + j); }, 400.0, 0.0);
  tree.slide(moved.view());
  EXPECT_EQ(tree.merged_colors().size(), tree.positions().size() - tree.merged_base());
  EXPECT_GE(tree.merged_colors().size(), soup.v.size()) << "the input vertices, plus any made by splitting";
  Camera c;
  c.eye = {2000.0, -300.0, 700.0};
  Frame f;
  TraversalOptions o;
  o.cull = false;
  tree.traverse(c, o, f);
  EXPECT_NEAR(drawn_merged_area(tree, f), soup.area, 1e-6 * soup.area);
}

TEST(Merge, RejectsIndicesOutOfRangeAndMismatchedColours) {
  TestWindow w(4, [](int, int) { return 0.0f; });
  TerrainTree tree(w.view(), 2);
  const std::vector<glm::dvec3> v{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  const std::vector<glm::u8vec4> c(3, glm::u8vec4(255));
  EXPECT_THROW(tree.merge(v, c, std::vector<std::uint32_t>{0, 1, 3}), std::invalid_argument);
  EXPECT_THROW(tree.merge(v, std::vector<glm::u8vec4>(2), std::vector<std::uint32_t>{0, 1, 2}), std::invalid_argument);
  EXPECT_THROW(tree.merge(v, c, std::vector<std::uint32_t>{0, 1}), std::invalid_argument);
}

}  // namespace
}  // namespace terravol::mrbsp
