// TerrainTree::memory(): what the tree holds, by part, and that merging and sliding leave it
// sized to the current content (no capacity kept from a larger merge before).
#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "mrbsp/terrain_tree.h"
#include "tree_test_util.h"

namespace terravol::mrbsp {
namespace {

using test::SlidingTerrain;
using test::TestWindow;

// `count` random triangles through a window of 16 cells of 100 m (x and y in [-100, 1700]),
// big ones spanning many split planes, so that merging splits them and copies them per LOD.
struct Triangles {
  std::vector<glm::dvec3> v;
  std::vector<glm::u8vec4> c;
  std::vector<std::uint32_t> t;
};

Triangles random_triangles(std::uint32_t seed, int count) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> xy(-100.0, 1700.0), z(-50.0, 500.0);
  Triangles s;
  for (int k = 0; k < count; ++k) {
    const auto base = static_cast<std::uint32_t>(s.v.size());
    for (int corner = 0; corner < 3; ++corner) s.v.emplace_back(xy(rng), xy(rng), z(rng));
    s.c.insert(s.c.end(), 3, glm::u8vec4(40, 200, 255, 90));
    s.t.insert(s.t.end(), {base, base + 1, base + 2});
  }
  return s;
}

float hills(int i, int j) { return 200.0f + 120.0f * std::sin(0.5f * static_cast<float>(i)) * std::cos(0.4f * static_cast<float>(j)); }

TEST(TerrainTreeMemory, VerticesAreTheLatticeAndItsWalls) {
  const TestWindow w(16, hills);
  const TerrainTree tree(w.view(), 4);
  const MemoryStats m = tree.memory();
  EXPECT_EQ(m.samples, 17u * 17u);
  EXPECT_EQ(m.vertices, (17u * 17u + 8u * 17u) * sizeof(glm::vec3)) << "the samples, and a top and bottom per side sample";
  EXPECT_EQ(m.merged, 0u) << "nothing merged yet";
  EXPECT_GT(m.nodes, 0u);
  EXPECT_EQ(m.total(), m.nodes + m.vertices + m.merged);
}

TEST(TerrainTreeMemory, MergingTrianglesIncreasesMergedAndNotNodesOrVertices) {
  const TestWindow w(16, hills);
  TerrainTree tree(w.view(), 4);
  const MemoryStats before = tree.memory();
  const Triangles s = random_triangles(5, 40);
  tree.merge(s.v, s.c, s.t);
  const MemoryStats after = tree.memory();
  EXPECT_EQ(after.nodes, before.nodes);
  EXPECT_EQ(after.vertices, before.vertices);
  // At least the kept inputs and each merged vertex's position and colour.
  const std::size_t merged_vertices = tree.positions().size() - tree.merged_base();
  EXPECT_GT(merged_vertices, s.v.size()) << "big triangles are split";
  const std::size_t floor = s.v.size() * sizeof(glm::dvec3) + s.c.size() * sizeof(glm::u8vec4) +
                            s.t.size() * sizeof(std::uint32_t) + merged_vertices * (sizeof(glm::vec3) + sizeof(glm::u8vec4));
  EXPECT_GT(after.merged, floor) << "polygons and leaf BSPs come on top";
}

TEST(TerrainTreeMemory, MergingNothingAfterwardsGivesBackAllMergedMemory) {
  const TestWindow w(16, hills);
  TerrainTree tree(w.view(), 4);
  const Triangles s = random_triangles(6, 60);
  tree.merge(s.v, s.c, s.t);
  ASSERT_GT(tree.memory().merged, 0u);
  tree.merge({}, {}, {});
  EXPECT_EQ(tree.memory().merged, 0u);
  EXPECT_EQ(tree.positions().size(), tree.merged_base());
}

// A merge holds what it needs, whatever was merged before: a small merge after a large one
// holds exactly what the small one holds on a new tree (no capacity kept from the large one).
TEST(TerrainTreeMemory, ASmallMergeAfterALargeOneHoldsWhatItHoldsAlone) {
  const TestWindow w(16, hills);
  const Triangles large = random_triangles(7, 120), small = random_triangles(8, 6);
  TerrainTree reused(w.view(), 4);
  reused.merge(large.v, large.c, large.t);
  const std::size_t large_bytes = reused.memory().merged;
  reused.merge(small.v, small.c, small.t);
  TerrainTree fresh(w.view(), 4);
  fresh.merge(small.v, small.c, small.t);
  EXPECT_EQ(reused.memory().merged, fresh.memory().merged);
  EXPECT_LT(reused.memory().merged, large_bytes / 4);
}

// Sliding (section 4.3) keeps the node structure and recomputes everything in place; the
// merged polygons merged again into the moved window take what they take in a tree built
// there, not the larger of that and what the old window held.
TEST(TerrainTreeMemory, SlidingKeepsNodesAndHoldsWhatATreeBuiltThereHolds) {
  const SlidingTerrain terrain(31);
  const TestWindow a = terrain.window_at(0, 0), b = terrain.window_at(24, 16);
  // Triangles over the first window only: after the slide most of them lie outside the moved
  // window and are split by fewer of its planes.
  const Triangles s = random_triangles(9, 80);
  TerrainTree slid(a.view(), 4);
  slid.merge(s.v, s.c, s.t);
  const MemoryStats before = slid.memory();
  slid.slide(b.view());
  const MemoryStats after = slid.memory();
  EXPECT_EQ(after.nodes, before.nodes);
  EXPECT_EQ(after.vertices, before.vertices);
  EXPECT_EQ(after.samples, before.samples);

  TerrainTree fresh(b.view(), 4);
  fresh.merge(s.v, s.c, s.t);
  EXPECT_EQ(after.merged, fresh.memory().merged);
  EXPECT_NE(after.merged, before.merged) << "the moved window splits the triangles otherwise";
}

TEST(TerrainTreeMemory, GrowsAboutFourfoldWhenTheWindowSideDoubles) {
  const TestWindow small(64, hills), large(128, hills);
  // The same coarsest level (8 x 8 cells), so one more level for the larger window.
  const TerrainTree a(small.view(), 4), b(large.view(), 5);
  const double ratio = static_cast<double>(b.memory().total()) / static_cast<double>(a.memory().total());
  EXPECT_GT(ratio, 3.6);
  EXPECT_LT(ratio, 4.4);
  const double nodes_ratio = static_cast<double>(b.memory().nodes) / static_cast<double>(a.memory().nodes);
  EXPECT_NEAR(nodes_ratio, 4.0, 0.3);
  EXPECT_EQ(b.memory().samples, 129u * 129u);
}

// The figure in the contract: about 16 bytes per lattice sample (its position, 12 bytes, and
// 12 bytes per cell above the finest level, of which there is about a third per sample).
TEST(TerrainTreeMemory, HoldsAbout16BytesPerLatticeSample) {
  const TestWindow w(256, hills);
  const TerrainTree tree(w.view(), 6);
  const MemoryStats m = tree.memory();
  const double per_sample = static_cast<double>(m.total()) / static_cast<double>(m.samples);
  EXPECT_GT(per_sample, 15.0);
  EXPECT_LT(per_sample, 17.0);
}

}  // namespace
}  // namespace terravol::mrbsp
