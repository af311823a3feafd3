#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <initializer_list>
#include <limits>
#include <random>
#include <thread>
#include <vector>

#include "mrbsp/terrain_tree.h"
#include "tree_test_util.h"

namespace terravol::mrbsp {
namespace {

using test::drawn_merged_area;
using test::order_violations;
using test::hilly_tree;
using test::TestWindow;

// Random triangles through the terrain's volume (big and small), plus two lying exactly in
// split planes (the root's x = 800 and a y plane), all translucent.
struct Soup : test::TriangleSoup {
  double area = 0.0;
  void add(glm::dvec3 a, glm::dvec3 b, glm::dvec3 d) {
    const auto base = static_cast<std::uint32_t>(v.size());
    v.insert(v.end(), {a, b, d});
    c.insert(c.end(), 3, glm::u8vec4(200, 100, 50, 120));
    t.insert(t.end(), {base, base + 1, base + 2});
    area += 0.5 * glm::length(glm::cross(b - a, d - a));
  }
};

// `count` triangles with corners in [xy0, xy1]^2 x [z0, z1], every second one big (corners
// anywhere there) and the others small (within `small` of their first corner).
struct SoupExtent {
  double xy0, xy1, z0, z1, small;
};
Soup random_triangles(std::mt19937& rng, int count, const SoupExtent& e) {
  std::uniform_real_distribution<double> xy(e.xy0, e.xy1), z(e.z0, e.z1), small(-e.small, e.small);
  Soup s;
  for (int k = 0; k < count; ++k) {
    const glm::dvec3 a(xy(rng), xy(rng), z(rng));
    if (k % 2) {
      s.add(a, a + glm::dvec3(small(rng), small(rng), small(rng)), a + glm::dvec3(small(rng), small(rng), small(rng)));
    } else {
      s.add(a, {xy(rng), xy(rng), z(rng)}, {xy(rng), xy(rng), z(rng)});
    }
  }
  return s;
}

// Over the 16-cell test window. With `in_planes`, two more lie exactly in split planes; the
// area tests leave them out, since the brute-force reference counts a polygon on a boundary in
// both regions it bounds.
Soup random_soup(std::mt19937& rng, int count, bool in_planes = true) {
  Soup s = random_triangles(rng, count, {-100.0, 1700.0, -50.0, 500.0, 150.0});
  if (in_planes) {
    s.add({800.0, 100.0, 0.0}, {800.0, 900.0, 50.0}, {800.0, 500.0, 450.0});   // in the root plane
    s.add({300.0, 400.0, 20.0}, {1200.0, 400.0, 30.0}, {700.0, 400.0, 380.0});  // in a y plane
  }
  return s;
}

// A camera at `eye` looking along `forward` (not vertical), 60 degrees wide.
Camera camera_at(const glm::dvec3& eye, glm::dvec3 forward) { return test::looking(eye, forward, 60.0, 320, 200, 0.5); }

// A seeded eye (x and y from `xy`, z from `z`) and a camera from it looking along a seeded
// direction whose z component is pitch + spread * U(-1, 1).
struct SeededView {
  glm::dvec3 eye;
  Camera camera;
};
SeededView seeded_view(std::mt19937& rng, std::uniform_real_distribution<double>& xy, std::uniform_real_distribution<double>& z,
                       double pitch, double spread) {
  std::uniform_real_distribution<double> dir(-1.0, 1.0);
  const glm::dvec3 eye(xy(rng), xy(rng), z(rng));
  return {eye, camera_at(eye, {dir(rng), dir(rng), pitch + spread * dir(rng)})};
}

// The window's footprint: 16 cells of 100 m from the origin.
constexpr double kX0 = 0.0, kX1 = 1600.0;

// At each LOD threshold, with culling off, the merged area drawn from `c` is the soup's area
// above the terrain drawn there (brute-force clipping), and a fair share of the soup is drawn.
void expect_drawn_area_at_thresholds(const TerrainTree& tree, const Camera& c, const Soup& soup,
                                     std::initializer_list<float> thresholds, Frame& f) {
  for (float t : thresholds) {
    TraversalOptions o;
    o.cull = false;
    o.threshold_px = t;
    tree.traverse(c, o, f);
    const double expected = test::area_above_drawn_terrain(tree, f, soup, kX0, kX1, kX0, kX1);
    EXPECT_GT(expected, 0.2 * soup.area);
    EXPECT_NEAR(drawn_merged_area(tree, f), expected, 1e-6 * soup.area) << "threshold " << t;
  }
}

TEST(Merge, MergedAndTerrainTrianglesAreInBackToFrontOrderFromRandomEyes) {
  std::mt19937 rng(77);
  TestWindow w(16, [](int, int) { return 0.0f; });
  TerrainTree tree = hilly_tree(rng, w);
  const Soup soup = random_soup(rng, 24);
  const MergeStats stats = tree.merge(soup.v, soup.c, soup.t);
  EXPECT_EQ(stats.input_triangles, soup.size());
  EXPECT_GT(stats.stored_polygons, stats.input_triangles) << "spanning triangles are split and copied per LOD";
  std::uniform_real_distribution<double> xy(-300.0, 1900.0), z(-200.0, 900.0), dir(-1.0, 1.0);
  Frame f;
  std::size_t merged = 0;
  for (int trial = 0; trial < 40; ++trial) {
    glm::dvec3 eye(xy(rng), xy(rng), z(rng));
    if (trial % 3 == 0) eye.x = 800.0;
    Camera c = camera_at(eye, {dir(rng), dir(rng), 0.6 * dir(rng)});
    TraversalOptions o;
    o.cull = trial % 2 == 0;  // culling by content boxes must keep the order of what it keeps
    o.threshold_px = 2.0f * static_cast<float>(1 << (trial % 7));
    o.front_to_back = trial % 5 == 4;
    tree.traverse(c, o, f);
    merged += static_cast<std::size_t>(std::count(f.level.begin(), f.level.end(), kMergedLevel));
    EXPECT_EQ(order_violations(tree, f, eye, 200, rng, !o.front_to_back), 0) << "trial " << trial;
  }
  EXPECT_GT(merged, 0u);
}

// Each visible part of each merged triangle is drawn exactly once, whatever the LOD choice:
// copies live in every alternative, one alternative is drawn per region, and what is dropped
// lies below the terrain drawn there. The reference clips the input triangles against the
// frame's terrain triangles by brute force.
TEST(Merge, DrawnMergedAreaIsTheInputAreaAboveTheDrawnTerrainAtEveryThreshold) {
  std::mt19937 rng(3);
  TestWindow w(16, [](int, int) { return 0.0f; });
  TerrainTree tree = hilly_tree(rng, w);
  const Soup soup = random_soup(rng, 30, false);
  tree.merge(soup.v, soup.c, soup.t);
  EXPECT_GT(tree.merge_stats().dropped_pieces, 0u) << "the soup reaches below the terrain";
  Camera c;
  c.eye = {-400.0, -300.0, 700.0};
  Frame f;
  expect_drawn_area_at_thresholds(tree, c, soup, {0.5f, 4.0f, 64.0f, 10000.0f}, f);
  TraversalOptions full;
  full.cull = false;
  full.full_res = true;
  tree.traverse(c, full, f);
  EXPECT_NEAR(drawn_merged_area(tree, f), test::area_above_drawn_terrain(tree, f, soup, kX0, kX1, kX0, kX1),
              1e-6 * soup.area);
}

// A surface of more than two chunks of triangles (TerrainTree::Impl::distribute_all sends it
// through the tree in parallel parts and joins their pieces): a wavy sheet over the whole
// window, through the terrain's heights. Every visible part is drawn once, in order.
TEST(Merge, ALargeSurfaceSentInChunksDrawsItsWholeVisibleAreaInOrder) {
  std::mt19937 rng(11);
  TestWindow w(16, [](int, int) { return 0.0f; });
  TerrainTree tree = hilly_tree(rng, w);
  Soup sheet;
  constexpr int kCols = 120, kRows = 110;  // 26,400 triangles
  const auto at = [](int i, int j) {
    const double x = -50.0 + 1700.0 * i / kCols, y = -50.0 + 1700.0 * j / kRows;
    return glm::dvec3(x, y, 260.0 + 120.0 * std::sin(x / 170.0) * std::cos(y / 230.0));
  };
  for (int j = 0; j < kRows; ++j)
    for (int i = 0; i < kCols; ++i) {
      sheet.add(at(i, j), at(i + 1, j), at(i + 1, j + 1));
      sheet.add(at(i, j), at(i + 1, j + 1), at(i, j + 1));
    }
  const MergeStats stats = tree.merge(sheet.v, sheet.c, sheet.t);
  EXPECT_EQ(stats.input_triangles, sheet.size());
  EXPECT_GT(stats.dropped_pieces, 0u) << "the sheet dips below the terrain";
  Camera c;
  c.eye = {-400.0, -300.0, 900.0};
  Frame f;
  expect_drawn_area_at_thresholds(tree, c, sheet, {1.0f, 64.0f}, f);
  std::uniform_real_distribution<double> xy(0.0, 1600.0), dir(-1.0, 1.0);
  for (int trial = 0; trial < 6; ++trial) {
    const glm::dvec3 eye(xy(rng), xy(rng), 450.0 + 100.0 * trial);
    Camera cam = camera_at(eye, {dir(rng), dir(rng), -0.5});
    TraversalOptions o;
    o.cull = trial % 2 == 0;
    tree.traverse(cam, o, f);
    EXPECT_EQ(order_violations(tree, f, eye, 100, rng, true), 0) << "trial " << trial;
  }
}

// The last pass of a traversal writes large frames in parallel chunks of the draw order and
// joins them: from random eyes, with and without culling, back to front and front to back,
// the chunked frame keeps the brute-force ray order and is the serial one triangle for
// triangle, with the same crack fills; so is a chunked frame of a tree of terrain alone.
TEST(Merge, AFrameWrittenInParallelChunksIsTheSerialFrameTriangleForTriangle) {
  std::mt19937 rng(19);
  TestWindow w(16, [](int, int) { return 0.0f; });
  TerrainTree tree = hilly_tree(rng, w);
  Soup soup = random_triangles(rng, 600, {-100.0, 1700.0, -50.0, 500.0, 40.0});
  tree.merge(soup.v, soup.c, soup.t);
  // And a tree of terrain alone, whose chunks are cut by counting cells.
  std::mt19937 bare_rng(20);
  TestWindow bare_window(16, [](int, int) { return 0.0f; });
  const TerrainTree bare = hilly_tree(bare_rng, bare_window);
  std::uniform_real_distribution<double> xy(-300.0, 1900.0), z(50.0, 900.0);
  Frame serial, chunked;
  std::size_t merged = 0;
  for (int trial = 0; trial < 24; ++trial) {
    const auto [eye, c] = seeded_view(rng, xy, z, -0.4, 0.3);
    TraversalOptions o;
    o.cull = trial % 2 == 0;
    o.front_to_back = trial % 3 == 2;
    o.threshold_px = 1.0f + static_cast<float>(trial % 4);
    o.parallel_min_triangles = std::numeric_limits<std::size_t>::max();
    tree.traverse(c, o, serial);
    o.parallel_min_triangles = 0;
    tree.traverse(c, o, chunked);
    // Against the brute-force ray order too, which the serial frame is held to elsewhere.
    EXPECT_EQ(order_violations(tree, chunked, eye, 40, rng, !o.front_to_back), 0) << "trial " << trial;
    ASSERT_EQ(chunked.indices, serial.indices) << "trial " << trial;
    EXPECT_EQ(chunked.level, serial.level) << "trial " << trial;
    EXPECT_EQ(chunked.crack_triangles, serial.crack_triangles) << "trial " << trial;
    merged += static_cast<std::size_t>(std::count(serial.level.begin(), serial.level.end(), kMergedLevel));
    o.parallel_min_triangles = std::numeric_limits<std::size_t>::max();
    bare.traverse(c, o, serial);
    o.parallel_min_triangles = 0;
    bare.traverse(c, o, chunked);
    ASSERT_EQ(chunked.indices, serial.indices) << "terrain alone, trial " << trial;
    EXPECT_EQ(chunked.level, serial.level) << "terrain alone, trial " << trial;
  }
  EXPECT_GT(merged, 600u);
}

// The LOD choice decides the subtrees below level 1 in parallel once a Frame's traversals are
// large, and the walk of the draw order walks them in parallel, building the low alternatives
// it draws for the first time after it (their vertices flushed in the serial walk's order).
// Two trees made alike over a 64-cell window with merged triangles, one traversed serially
// and one split, from seeded eyes, with and without culling, under both metrics: the split
// frame is the serial one vertex for vertex (the same cells visited, drawn and balanced, the
// same slots built), in the brute-force ray order.
TEST(Merge, AnLodChoiceAndWalkInParallelSubtreesDrawTheSerialFrame) {
  std::mt19937 rng(23), rng_split(23);
  TestWindow w(64, [](int, int) { return 0.0f; }), w_split(64, [](int, int) { return 0.0f; });
  TerrainTree serial_tree = hilly_tree(rng, w), split_tree = hilly_tree(rng_split, w_split);
  const Soup soup = random_triangles(rng, 400, {-100.0, 6500.0, -50.0, 500.0, 60.0});
  serial_tree.merge(soup.v, soup.c, soup.t);
  split_tree.merge(soup.v, soup.c, soup.t);
  ASSERT_GT(serial_tree.merge_stats().pending_slots, 0u) << "low alternatives must wait to be built";
  std::uniform_real_distribution<double> xy(-500.0, 6900.0), z(300.0, 2500.0);
  Frame serial, split;
  std::size_t balanced = 0, split_frames = 0;
  for (int trial = 0; trial < 24; ++trial) {
    const auto [eye, c] = seeded_view(rng, xy, z, -0.6, 0.4);
    TraversalOptions o;
    o.cull = trial % 3 != 0;
    o.metric = trial % 4 == 3 ? LodMetric::kArea : LodMetric::kError;
    o.threshold_px = o.metric == LodMetric::kArea ? 200.0f : 0.5f + static_cast<float>(trial % 3);
    o.parallel_min_nodes = std::numeric_limits<std::size_t>::max();
    serial_tree.traverse(c, o, serial);
    o.parallel_min_nodes = 0;
    split_tree.traverse(c, o, split);
    split_frames += split.subtree_roots_.empty() ? 0 : 1;
    EXPECT_EQ(order_violations(split_tree, split, eye, 40, rng, true), 0) << "trial " << trial;
    ASSERT_EQ(split.indices, serial.indices) << "trial " << trial;
    EXPECT_EQ(split.level, serial.level) << "trial " << trial;
    EXPECT_EQ(split.nodes_visited, serial.nodes_visited) << "trial " << trial;
    EXPECT_EQ(split.leaves, serial.leaves) << "trial " << trial;
    EXPECT_EQ(split.lod_histogram, serial.lod_histogram) << "trial " << trial;
    EXPECT_EQ(split.balanced_cells, serial.balanced_cells) << "trial " << trial;
    EXPECT_EQ(split.crack_triangles, serial.crack_triangles) << "trial " << trial;
    EXPECT_EQ(split_tree.merge_stats().lazy_built_slots, serial_tree.merge_stats().lazy_built_slots) << "trial " << trial;
    EXPECT_EQ(split_tree.positions().size(), serial_tree.positions().size()) << "trial " << trial;
    balanced += serial.balanced_cells;
  }
  EXPECT_GT(balanced, 0u) << "the balance pass must be exercised";
  EXPECT_GT(split_frames, 16u) << "and the split, where some level-0 cell in view is refined";
  EXPECT_GT(split_tree.merge_stats().lazy_built_slots, 2u) << "and slots built by the split walks";
}

// Culling by content boxes: from cameras inside and beside the merged triangles, low over the
// ground and looking up, down and level, the merged area drawn inside the view frustum is the
// input's visible area inside it (the reference clips the inputs to the frustum, derived by
// the test from the camera, and to the terrain drawn at the same LOD without culling, since a
// piece above culled terrain may still be in view).
TEST(Merge, WithCullingTheDrawnAreaInsideTheFrustumIsTheVisibleInputInsideIt) {
  std::mt19937 rng(41);
  TestWindow w(16, [](int, int) { return 0.0f; });
  TerrainTree tree = hilly_tree(rng, w);
  const Soup soup = random_soup(rng, 40, false);
  tree.merge(soup.v, soup.c, soup.t);
  std::uniform_real_distribution<double> xy(-200.0, 1800.0), z(250.0, 700.0), dir(-1.0, 1.0), pitch(-0.8, 0.8);
  Frame f, unculled;
  double seen = 0.0;
  for (int trial = 0; trial < 60; ++trial) {
    const glm::dvec3 eye(xy(rng), xy(rng), z(rng));
    const Camera c = camera_at(eye, {dir(rng), dir(rng), pitch(rng)});
    TraversalOptions o;
    o.threshold_px = 1.0f + static_cast<float>(trial % 5);
    tree.traverse(c, o, f);
    o.cull = false;
    tree.traverse(c, o, unculled);
    const auto frustum = test::frustum_of(c);
    const double expected = test::area_above_drawn_terrain(tree, unculled, soup, kX0, kX1, kX0, kX1, frustum);
    EXPECT_NEAR(drawn_merged_area(tree, f, frustum), expected, 1e-6 * soup.area + 1e-3) << "trial " << trial;
    seen += expected;
  }
  EXPECT_GT(seen, 0.0);
}

TEST(Merge, SlidingMergesThePolygonsAgainIntoTheMovedWindow) {
  std::mt19937 rng(12);
  TestWindow w(16, [](int, int) { return 0.0f; });
  TerrainTree tree = hilly_tree(rng, w);
  const Soup soup = random_soup(rng, 10, false);
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
  EXPECT_NEAR(drawn_merged_area(tree, f), test::area_above_drawn_terrain(tree, f, soup, 400.0, 2000.0, 0.0, 1600.0),
              1e-6 * soup.area);
}

// Triangles over the 64 x 64-sample terrain of SlidingTerrain (6.3 km): big and small ones,
// through its volume.
Soup soup_over_sliding_terrain(std::mt19937& rng, int count) {
  return random_triangles(rng, count, {-150.0, 3000.0, -50.0, 450.0, 200.0});
}

// A slide by whole level-0 cells over the same terrain keeps the slots and pieces of the cells
// in both windows and merges only what lies beyond them (section 4.3): after each slide of a
// walk, fewer slots are built than a merge of everything builds, and from random eyes the
// frames draw the terrain of a tree built there anew, the merged area that tree draws and the
// brute-force reference finds, in back-to-front order.
TEST(Merge, ASlideByWholeCellsKeepsWhatStaysAndDrawsWhatAFreshMergeDraws) {
  std::mt19937 rng(1997);
  const test::SlidingTerrain terrain(5);
  const Soup soup = soup_over_sliding_terrain(rng, 60);
  TerrainTree slid(terrain.window_at(0, 0).view(), 3);  // level 0: 4 x 4 cells of 4 x 4 samples
  slid.merge(soup.v, soup.c, soup.t);
  const int walk[][2] = {{8, 4}, {4, 16}, {16, 16}, {8, 8}, {12, 4}, {12, 12}, {12, 12}};
  for (const auto& at : walk) {
    const TestWindow w = terrain.window_at(at[0], at[1]);
    slid.slide(w.view());
    const MergeStats& moved = slid.merge_stats();
    TerrainTree fresh(w.view(), 3);
    const MergeStats all = fresh.merge(soup.v, soup.c, soup.t);
    EXPECT_LT(moved.rebuilt_slots, all.rebuilt_slots) << "at " << at[0] << ", " << at[1];
    EXPECT_EQ(slid.positions().size() - slid.merged_base(), slid.merged_colors().size());
    const double x0 = 100.0 * at[0], y0 = 100.0 * at[1];
    std::uniform_real_distribution<double> xy(-300.0, 1900.0), z(0.0, 700.0), dir(-1.0, 1.0);
    Frame fs, ff;
    for (int trial = 0; trial < 8; ++trial) {
      const glm::dvec3 eye(x0 + xy(rng), y0 + xy(rng), 350.0 + z(rng));
      const Camera c = camera_at(eye, {dir(rng), dir(rng), -0.7});
      TraversalOptions o;
      o.cull = false;
      o.threshold_px = 1.0f + static_cast<float>(trial);
      slid.traverse(c, o, fs);
      fresh.traverse(c, o, ff);
      std::vector<std::uint32_t> terrain_s, terrain_f;
      for (std::size_t t = 0; t < fs.level.size(); ++t)
        if (fs.level[t] != kMergedLevel) terrain_s.insert(terrain_s.end(), fs.indices.begin() + 3 * t, fs.indices.begin() + 3 * t + 3);
      for (std::size_t t = 0; t < ff.level.size(); ++t)
        if (ff.level[t] != kMergedLevel) terrain_f.insert(terrain_f.end(), ff.indices.begin() + 3 * t, ff.indices.begin() + 3 * t + 3);
      EXPECT_EQ(terrain_s, terrain_f);
      const double expected = test::area_above_drawn_terrain(slid, fs, soup, x0, x0 + 1600.0, y0, y0 + 1600.0);
      EXPECT_NEAR(drawn_merged_area(slid, fs), expected, 1e-6 * soup.area) << "trial " << trial;
      EXPECT_NEAR(drawn_merged_area(slid, fs), drawn_merged_area(fresh, ff), 1e-6 * soup.area) << "trial " << trial;
      EXPECT_EQ(order_violations(slid, fs, eye, 150, rng, true), 0) << "trial " << trial;
    }
  }
}

// A copy is independent (terravol view slides a copy on a worker while frames go on): the copy slid
// and traversed (building low alternatives on first use) holds and draws what the original
// slid the same way does, and the original, left alone meanwhile, draws what it drew before.
TEST(Merge, ACopySlidAndTraversedLeavesTheOriginalAsItWas) {
  std::mt19937 rng(2026);
  const test::SlidingTerrain terrain(5);
  const Soup soup = soup_over_sliding_terrain(rng, 60);
  TerrainTree original(terrain.window_at(0, 0).view(), 3);
  original.merge(soup.v, soup.c, soup.t);
  const Camera c = camera_at({800.0, -200.0, 900.0}, {0.1, 1.0, -0.6});
  TraversalOptions o;
  o.threshold_px = 3.0f;
  Frame before, f;
  original.traverse(c, o, before);
  const std::vector<glm::vec3> positions = original.positions();
  const std::vector<glm::u8vec4> colors = original.merged_colors();

  TerrainTree copy(original);
  TerrainTree reference(terrain.window_at(0, 0).view(), 3);
  reference.merge(soup.v, soup.c, soup.t);
  reference.traverse(c, o, f);
  for (const auto& at : {std::array{8, 4}, std::array{4, 12}}) {
    copy.slide(terrain.window_at(at[0], at[1]).view());
    reference.slide(terrain.window_at(at[0], at[1]).view());
    Frame fc, fr;
    const Camera moved = camera_at({100.0 * at[0] + 800.0, 100.0 * at[1] - 200.0, 900.0}, {0.1, 1.0, -0.6});
    copy.traverse(moved, o, fc);
    reference.traverse(moved, o, fr);
    EXPECT_EQ(fc.indices, fr.indices) << "at " << at[0] << ", " << at[1];
    EXPECT_EQ(copy.positions(), reference.positions());
    EXPECT_EQ(copy.merged_colors(), reference.merged_colors());
    EXPECT_GT(drawn_merged_area(copy, fc), 0.0);
    EXPECT_EQ(order_violations(copy, fc, moved.eye, 150, rng, true), 0) << "against the brute-force ray order";
  }
  EXPECT_EQ(original.positions(), positions);
  EXPECT_EQ(original.merged_colors(), colors);
  original.traverse(c, o, f);
  EXPECT_EQ(f.indices, before.indices);
  EXPECT_EQ(order_violations(original, f, c.eye, 150, rng, true), 0);
}

// A copy shares the original's small BSPs until one of the two changes them (copy on write):
// the copy slid and traversed on another thread while the original is edited, traversed and
// tidied on this one, each ends holding and drawing what the same steps make of a tree alone.
TEST(Merge, ACopySlidOnAnotherThreadWhileTheOriginalIsEditedEndsAsIfEachWereAlone) {
  std::mt19937 rng(2027);
  const test::SlidingTerrain terrain(5);
  const Soup a = soup_over_sliding_terrain(rng, 50), b = soup_over_sliding_terrain(rng, 30),
             b2 = soup_over_sliding_terrain(rng, 30);
  const auto input = [](const Soup& s) { return SurfaceInput{s.v, s.c, s.t}; };
  const std::uint32_t ids[2] = {1, 2};
  const SurfaceInput both[2] = {input(a), input(b)};
  const Camera c = camera_at({800.0, -200.0, 900.0}, {0.1, 1.0, -0.6});
  TraversalOptions o;
  o.threshold_px = 3.0f;
  // The common start: merged, then a frame (which builds the low slots it draws).
  const auto start = [&] {
    TerrainTree t(terrain.window_at(0, 0).view(), 3);
    t.set_surfaces(ids, both);
    Frame f;
    t.traverse(c, o, f);
    return t;
  };
  struct Result {
    std::vector<std::uint32_t> indices;
    std::vector<glm::vec3> positions;
    std::vector<glm::u8vec4> colors;
  };
  const auto slide_steps = [&](TerrainTree& t) {
    Result r;
    for (const auto& at : {std::array{8, 4}, std::array{4, 12}, std::array{0, 0}}) {
      t.slide(terrain.window_at(at[0], at[1]).view());
      Frame f;
      t.traverse(camera_at({100.0 * at[0] + 800.0, 100.0 * at[1] - 200.0, 900.0}, {0.1, 1.0, -0.6}),
                 o, f);
      r.indices.insert(r.indices.end(), f.indices.begin(), f.indices.end());
    }
    r.positions = t.positions();
    r.colors = t.merged_colors();
    return r;
  };
  const auto edit_steps = [&](TerrainTree& t) {
    Result r;
    for (int k = 0; k < 4; ++k) {
      t.set_surface(2, input(k % 2 ? b : b2));
      Frame f;
      t.traverse(camera_at({300.0 + 200.0 * k, -300.0, 700.0}, {0.2, 1.0, -0.5}), o, f);
      r.indices.insert(r.indices.end(), f.indices.begin(), f.indices.end());
      if (k == 2) t.tidy();
    }
    r.positions = t.positions();
    r.colors = t.merged_colors();
    return r;
  };
  TerrainTree alone_slid = start(), alone_edited = start();
  const Result slid_reference = slide_steps(alone_slid),
               edited_reference = edit_steps(alone_edited);

  TerrainTree original = start();
  TerrainTree copy(original);
  Result slid;
  std::thread worker([&] { slid = slide_steps(copy); });
  const Result edited = edit_steps(original);
  worker.join();
  const auto expect_same = [](const Result& got, const Result& alone, const char* which) {
    EXPECT_EQ(got.indices, alone.indices) << which;
    EXPECT_EQ(got.positions, alone.positions) << which;
    EXPECT_EQ(got.colors, alone.colors) << which;
  };
  expect_same(slid, slid_reference, "the copy, slid");
  expect_same(edited, edited_reference, "the original, edited");
  Frame f;
  copy.traverse(c, o, f);
  EXPECT_GT(drawn_merged_area(copy, f), 0.0);
  EXPECT_EQ(order_violations(copy, f, c.eye, 150, rng, true), 0);
  original.traverse(c, o, f);
  EXPECT_EQ(order_violations(original, f, c.eye, 150, rng, true), 0);
}

// Sliding there and back again keeps no more than a tree built at the end holds: the pieces
// and vertices of what left the window are dropped.
TEST(Merge, SlidingThereAndBackAgainHoldsWhatAFreshTreeHolds) {
  std::mt19937 rng(31);
  const test::SlidingTerrain terrain(6);
  const Soup soup = soup_over_sliding_terrain(rng, 40);
  TerrainTree slid(terrain.window_at(0, 0).view(), 3);
  slid.merge(soup.v, soup.c, soup.t);
  for (int k = 0; k < 12; ++k) slid.slide(terrain.window_at(k % 2 ? 0 : 8, k % 2 ? 0 : 4).view());
  TerrainTree fresh(terrain.window_at(0, 0).view(), 3);
  fresh.merge(soup.v, soup.c, soup.t);
  EXPECT_LT(slid.memory().merged, 2 * fresh.memory().merged);
  EXPECT_LT(slid.merge_stats().stored_polygons, 2 * fresh.merge_stats().stored_polygons);
}

// A window over other heights, or not moved by whole level-0 cells, is merged anew.
TEST(Merge, AWindowOverOtherTerrainIsMergedAnew) {
  std::mt19937 rng(8);
  const test::SlidingTerrain a(1), b(2);
  const Soup soup = soup_over_sliding_terrain(rng, 20);
  TerrainTree tree(a.window_at(0, 0).view(), 3);
  const MergeStats all = tree.merge(soup.v, soup.c, soup.t);
  tree.slide(b.window_at(4, 4).view());  // other heights where they overlap
  const std::size_t slots = tree.merge_stats().slots;
  EXPECT_EQ(tree.merge_stats().rebuilt_slots, slots);
  tree.slide(b.window_at(6, 4).view());  // two columns: not a whole level-0 cell
  EXPECT_EQ(tree.merge_stats().rebuilt_slots, tree.merge_stats().slots);
  EXPECT_GT(all.slots, 0u);
}

// A surface entirely above a cell's terrain stays whole at that cell: a flat sheet of 8
// triangles over one level-0 cell is stored as 8 pieces, and one below the terrain not at all.
TEST(Merge, PiecesAboveTheTerrainStayWholeAndPiecesBelowItAreDropped) {
  TestWindow w(16, [](int i, int j) { return static_cast<float>(10 * i + 5 * j); });
  TerrainTree tree(w.view(), 3);  // level 0: 4 x 4 cells of 400 m
  test::TriangleSoup sheet;
  const auto grid = [&](double z) {
    test::TriangleSoup s;
    for (int j = 0; j <= 2; ++j)
      for (int i = 0; i <= 2; ++i) {
        s.v.emplace_back(410.0 + 190.0 * i, 410.0 + 190.0 * j, z);
        s.c.emplace_back(10, 200, 10, 100);
      }
    for (std::uint32_t j = 0; j < 2; ++j)
      for (std::uint32_t i = 0; i < 2; ++i) {
        const std::uint32_t a = j * 3 + i;
        s.t.insert(s.t.end(), {a, a + 1, a + 4, a, a + 4, a + 3});
      }
    return s;
  };
  sheet = grid(500.0);  // the terrain reaches 240 m
  MergeStats stats = tree.merge(sheet.v, sheet.c, sheet.t);
  EXPECT_EQ(stats.stored_polygons, 8u);
  EXPECT_EQ(stats.slots, 1u);
  EXPECT_EQ(stats.dropped_pieces, 0u);
  const test::TriangleSoup under = grid(-100.0);
  stats = tree.merge(under.v, under.c, under.t);
  EXPECT_EQ(stats.stored_polygons, 0u);
  EXPECT_EQ(stats.slots, 0u);
  EXPECT_GT(stats.dropped_pieces, 0u);
}

// A small BSP of more pieces than one thread builds (SlotBuilder::kHalvedBuild, 2,048): 2,600
// small triangles above the terrain over one level-0 cell, all in its above slot, built in
// two halves at once and joined. It keeps the brute-force ray order from eyes among, above
// and beside the triangles, and draws each of them whole, once.
TEST(Merge, ASmallBspOfThousandsOfPiecesBuiltInTwoHalvesKeepsTheOrderAndTheArea) {
  std::mt19937 rng(11);
  TestWindow w(16, [](int i, int j) { return static_cast<float>(10 * i + 5 * j); });  // up to 240 m
  TerrainTree tree(w.view(), 3);  // level 0: 4 x 4 cells of 400 m
  std::uniform_real_distribution<double> xy(420.0, 780.0), z(300.0, 700.0), small(-12.0, 12.0);
  Soup soup;
  for (int k = 0; k < 2600; ++k) {
    const glm::dvec3 a(xy(rng), xy(rng), z(rng));
    const auto near_a = [&] { return a + glm::dvec3(small(rng), small(rng), small(rng)); };
    const glm::dvec3 b = near_a();
    soup.add(a, b, near_a());
  }
  const MergeStats stats = tree.merge(soup.v, soup.c, soup.t);
  EXPECT_EQ(stats.slots, 1u);
  EXPECT_GE(stats.stored_polygons, stats.input_triangles);
  std::uniform_real_distribution<double> eye_xy(0.0, 1600.0), eye_z(260.0, 1000.0);
  Frame f;
  for (int trial = 0; trial < 8; ++trial) {
    const SeededView view = seeded_view(rng, eye_xy, eye_z, -0.3, 0.5);
    TraversalOptions o;
    o.cull = false;
    tree.traverse(view.camera, o, f);
    EXPECT_NEAR(drawn_merged_area(tree, f), soup.area, 1e-6 * soup.area) << "trial " << trial;
    EXPECT_EQ(order_violations(tree, f, view.eye, 150, rng, true), 0) << "trial " << trial;
  }
}

// A height field on lines x = c and y = c (as a slice of a geographic volume lies on its
// lattice's meridians and parallels), wavy and entirely above the terrain: its small BSP
// separates its cells by those planes (axis_split) and cuts none of its triangles, and it
// keeps the brute-force ray order from eyes above, beside and below its crests.
TEST(Merge, AHeightFieldOnAxisLinesAboveTheTerrainIsStoredWithoutACut) {
  std::mt19937 rng(5);
  TestWindow w(16, [](int i, int j) { return static_cast<float>(10 * i + 5 * j); });
  TerrainTree tree(w.view(), 3);
  test::TriangleSoup sheet;
  constexpr int kCols = 48, kRows = 40;
  std::uniform_real_distribution<double> jitter(-0.3, 0.3);
  // Uneven lines over [400, 1200]^2, through the level-0 cells' planes x = 800 and y = 800
  // (the tree cuts what crosses its own planes; the test is about the small BSP's).
  std::vector<double> xs, ys;
  for (int i = 0; i <= kCols; ++i) xs.push_back(400.0 + 800.0 * (i + (i % (kCols / 2) ? jitter(rng) : 0.0)) / kCols);
  for (int j = 0; j <= kRows; ++j) ys.push_back(400.0 + 800.0 * (j + (j % (kRows / 2) ? jitter(rng) : 0.0)) / kRows);
  for (int j = 0; j <= kRows; ++j)
    for (int i = 0; i <= kCols; ++i) {
      sheet.v.emplace_back(xs[i], ys[j], 600.0 + 200.0 * std::sin(xs[i] / 140.0) * std::cos(ys[j] / 190.0));
      sheet.c.emplace_back(40, 90, 200, 110);
    }
  for (std::uint32_t j = 0; j < kRows; ++j)
    for (std::uint32_t i = 0; i < kCols; ++i) {
      const std::uint32_t a = j * (kCols + 1) + i, b = a + 1, d = a + kCols + 1, e = d + 1;
      if ((i + j) % 2) {
        sheet.t.insert(sheet.t.end(), {a, b, e, a, e, d});
      } else {
        sheet.t.insert(sheet.t.end(), {a, b, d, b, e, d});
      }
    }
  const MergeStats stats = tree.merge(sheet.v, sheet.c, sheet.t);
  EXPECT_EQ(stats.input_triangles, sheet.t.size() / 3);
  EXPECT_EQ(stats.stored_polygons, stats.input_triangles) << "no triangle is cut";
  std::uniform_real_distribution<double> xy(200.0, 1400.0), dir(-1.0, 1.0);
  Frame f;
  for (int trial = 0; trial < 6; ++trial) {
    const glm::dvec3 eye(xy(rng), xy(rng), 300.0 + 150.0 * trial);
    const Camera cam = camera_at(eye, {dir(rng), dir(rng), -0.4});
    TraversalOptions o;
    o.cull = trial % 2 == 0;
    tree.traverse(cam, o, f);
    EXPECT_EQ(order_violations(tree, f, eye, 100, rng, true), 0) << "trial " << trial;
  }
}

// An edit removes one surface's polygons and inserts its new ones (BSP insertion), touching
// only the slots they reach. After a sequence of edits the tree still draws every visible part
// of every surface once, in back-to-front order (brute force references as above), and a
// removed surface is gone.
TEST(Merge, EditsKeepTheOrderAndDrawEachVisiblePartOnce) {
  std::mt19937 rng(5);
  TestWindow w(16, [](int, int) { return 0.0f; });
  TerrainTree tree = hilly_tree(rng, w);
  const Soup a = random_soup(rng, 12, false), b = random_soup(rng, 12, false), b2 = random_soup(rng, 8, false),
             c = random_soup(rng, 12, false), d = random_soup(rng, 6, false);
  const auto input = [](const Soup& s) { return SurfaceInput{s.v, s.c, s.t}; };
  const auto joined = [](std::initializer_list<const Soup*> parts) {
    test::TriangleSoup all;
    for (const Soup* p : parts) {
      const auto base = static_cast<std::uint32_t>(all.v.size());
      all.v.insert(all.v.end(), p->v.begin(), p->v.end());
      all.c.insert(all.c.end(), p->c.begin(), p->c.end());
      for (std::uint32_t i : p->t) all.t.push_back(base + i);
    }
    return all;
  };
  const std::uint32_t ids[3] = {4, 9, 2};
  const SurfaceInput first[3] = {input(a), input(b), input(c)};
  tree.set_surfaces(ids, first);
  const std::size_t all_slots = tree.merge_stats().slots;

  const auto check = [&](const test::TriangleSoup& visible, const char* step) {
    std::uniform_real_distribution<double> xy(-300.0, 1900.0), z(250.0, 800.0), dir(-1.0, 1.0);
    Frame f;
    for (int trial = 0; trial < 12; ++trial) {
      const glm::dvec3 eye(xy(rng), xy(rng), z(rng));
      const Camera cam = camera_at(eye, {dir(rng), dir(rng), 0.5 * dir(rng)});
      TraversalOptions o;
      o.threshold_px = 1.0f + static_cast<float>(trial % 4);
      o.cull = trial % 2 == 0;
      tree.traverse(cam, o, f);
      EXPECT_EQ(order_violations(tree, f, eye, 150, rng, true), 0) << step << ", trial " << trial;
      if (!o.cull) {
        const double expected = test::area_above_drawn_terrain(tree, f, visible, kX0, kX1, kX0, kX1);
        EXPECT_NEAR(drawn_merged_area(tree, f), expected, 1e-6 * expected + 1e-3) << step << ", trial " << trial;
      }
    }
  };
  check(joined({&a, &b, &c}), "merged");
  const MergeStats edit = tree.set_surface(9, input(b2));
  EXPECT_LT(edit.rebuilt_slots, all_slots) << "an edit touches only the slots its surface reaches";
  EXPECT_EQ(edit.surfaces, 3u);
  check(joined({&a, &b2, &c}), "after replacing 9");
  tree.set_surface(9, SurfaceInput{});
  EXPECT_EQ(tree.merge_stats().surfaces, 2u);
  check(joined({&a, &c}), "after removing 9");
  tree.set_surface(7, input(d));
  tree.set_surface(4, input(b));
  check(joined({&b, &c, &d}), "after adding 7 and replacing 4");
  // A change small against what a slot holds is inserted into the slot's BSP, not built anew.
  const Soup e = random_soup(rng, 1, false);
  const MergeStats small = tree.set_surface(11, input(e));
  EXPECT_GT(small.inserted_slots, 0u);
  EXPECT_LE(small.inserted_slots, small.rebuilt_slots);
  check(joined({&b, &c, &d, &e}), "after adding one triangle as 11");
  // Edits wear the small BSPs (insertion cuts the new pieces by planes chosen for others);
  // tidy() builds the worn ones anew: fewer pieces, the same surfaces, in order.
  for (int k = 0; k < 6; ++k) tree.set_surface(7, input(k % 2 ? d : a));  // ends as d
  const MergeStats worn = tree.merge_stats();
  ASSERT_GT(worn.worn_slots, 0u) << "six replacements wear some slot";
  const MergeStats tidied = tree.tidy();
  EXPECT_EQ(tidied.rebuilt_slots, worn.worn_slots);
  EXPECT_EQ(tidied.worn_slots, 0u);
  EXPECT_LT(tidied.stored_polygons, worn.stored_polygons);
  check(joined({&b, &c, &d, &e}), "after tidying");
  EXPECT_EQ(tree.tidy().rebuilt_slots, 0u) << "nothing is worn any more";
}

// Texture coordinates ride along with the colours: on a sheet whose coordinates are a linear
// function of position, every merged vertex (input or made by a split) keeps that function's
// value; vertices of a surface without coordinates get (-1, -1).
TEST(Merge, TextureCoordinatesAreInterpolatedWhereverPiecesAreSplit) {
  std::mt19937 rng(21);
  TestWindow w(16, [](int, int) { return 0.0f; });
  TerrainTree tree = hilly_tree(rng, w);
  test::TriangleSoup sheet;
  std::vector<glm::vec2> tc;
  std::uniform_real_distribution<double> z(100.0, 450.0);
  for (int j = 0; j <= 4; ++j)
    for (int i = 0; i <= 4; ++i) {
      sheet.v.emplace_back(-50.0 + 420.0 * i, -50.0 + 420.0 * j, z(rng));
      sheet.c.emplace_back(20, 40, 200, 150);
      tc.emplace_back(static_cast<float>(sheet.v.back().x / 1000.0), static_cast<float>(sheet.v.back().y / 1000.0));
    }
  for (std::uint32_t j = 0; j < 4; ++j)
    for (std::uint32_t i = 0; i < 4; ++i) {
      const std::uint32_t a = j * 5 + i;
      sheet.t.insert(sheet.t.end(), {a, a + 1, a + 6, a, a + 6, a + 5});
    }
  const Soup plain = random_soup(rng, 10, false);
  const std::uint32_t ids[2] = {1, 2};
  const SurfaceInput inputs[2] = {{sheet.v, sheet.c, sheet.t, tc}, {plain.v, plain.c, plain.t}};
  tree.set_surfaces(ids, inputs);
  Frame f;
  TraversalOptions o;
  o.cull = false;
  o.full_res = true;
  tree.traverse(camera_at({-300, -300, 900}, {1, 1, -0.5}), o, f);
  const auto& p = tree.positions();
  const auto& t = tree.merged_tcoords();
  ASSERT_EQ(t.size(), p.size() - tree.merged_base());
  std::size_t textured = 0, plain_vertices = 0;
  for (std::size_t k = 0; k < t.size(); ++k) {
    if (t[k] == glm::vec2(-1.0f, -1.0f)) {  // the sheet's coordinates stay above -0.05
      ++plain_vertices;
      continue;
    }
    ++textured;
    EXPECT_NEAR(t[k].x, p[tree.merged_base() + k].x / 1000.0, 1e-4) << "vertex " << k;
    EXPECT_NEAR(t[k].y, p[tree.merged_base() + k].y / 1000.0, 1e-4) << "vertex " << k;
  }
  EXPECT_GT(textured, sheet.v.size()) << "the sheet is split";
  EXPECT_GT(plain_vertices, 0u);
  tree.set_surface(1, SurfaceInput{});
  EXPECT_TRUE(tree.merged_tcoords().empty()) << "no surface has coordinates any more";
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
