// Colour boxes drawn in the tree's exact order (mrbsp/color_boxes.h): against brute force.
#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "mrbsp/terrain_tree.h"
#include "tree_test_util.h"

namespace terravol::mrbsp {
namespace {

using test::frame_vertex;
using test::hilly_tree;
using test::order_violations;
using test::TestWindow;

// A grid of nx x ny x nz boxes over [x0, x1] x [y0, y1] x [z0, z1], in a back-to-front order
// for `eye`: farther on z first, then on y, then on x (index distances from the eye's cell);
// every pair of grid cells is then separated by a plane with the earlier one beyond it.
std::vector<ColorBox> grid_boxes(const glm::dvec3& eye, int nx, int ny, int nz, glm::dvec3 lo, glm::dvec3 hi,
                                 std::mt19937& rng) {
  std::uniform_int_distribution<int> c(0, 255), a(20, 200);
  const glm::dvec3 step = (hi - lo) / glm::dvec3(nx, ny, nz);
  struct Keyed {
    int key[3];
    ColorBox box;
  };
  std::vector<Keyed> all;
  const auto cell_of = [&](int axis, int n) {
    return static_cast<int>(std::floor((eye[axis] - lo[axis]) / step[axis])) + 0 * n;
  };
  const int e[3] = {cell_of(0, nx), cell_of(1, ny), cell_of(2, nz)};
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        Keyed kb;
        kb.key[0] = std::abs(k - e[2]);
        kb.key[1] = std::abs(j - e[1]);
        kb.key[2] = std::abs(i - e[0]);
        kb.box.lo = glm::vec3(lo + step * glm::dvec3(i, j, k));
        kb.box.hi = glm::vec3(lo + step * glm::dvec3(i + 1, j + 1, k + 1));
        for (auto& rgba : kb.box.rgba) rgba = glm::u8vec4(c(rng), c(rng), c(rng), a(rng));
        all.push_back(kb);
      }
  std::stable_sort(all.begin(), all.end(), [](const Keyed& p, const Keyed& q) {
    return std::lexicographical_compare(q.key, q.key + 3, p.key, p.key + 3);
  });
  std::vector<ColorBox> out;
  for (const Keyed& k : all) out.push_back(k.box);
  return out;
}

// Translucent triangles through the terrain's volume, some of them crossing the boxes.
test::TriangleSoup soup_of(std::mt19937& rng, int count) {
  std::uniform_real_distribution<double> xy(-100.0, 1700.0), z(-50.0, 550.0), small(-200.0, 200.0);
  test::TriangleSoup s;
  for (int k = 0; k < count; ++k) {
    const glm::dvec3 a(xy(rng), xy(rng), z(rng));
    const auto base = static_cast<std::uint32_t>(s.v.size());
    s.v.insert(s.v.end(), {a, a + glm::dvec3(small(rng), small(rng), small(rng)), a + glm::dvec3(small(rng), small(rng), small(rng))});
    s.c.insert(s.c.end(), 3, glm::u8vec4(90, 200, 60, 110));
    s.t.insert(s.t.end(), {base, base + 1, base + 2});
  }
  return s;
}

Camera camera_at(const glm::dvec3& eye, glm::dvec3 forward) { return test::looking(eye, forward, 60.0, 320, 200, 0.5); }

// The soup of the boxes' faces that face the eye (two triangles each).
test::TriangleSoup front_faces(const std::vector<ColorBox>& boxes, const glm::dvec3& eye) {
  test::TriangleSoup s;
  for (const ColorBox& b : boxes) {
    for (int f = 0; f < 6; ++f) {
      const int a = f / 2, u = (a + 1) % 3, v = (a + 2) % 3;
      if (!((f & 1) ? eye[a] > b.hi[a] : eye[a] < b.lo[a])) continue;
      glm::dvec3 q[4];
      const double us[4] = {b.lo[u], b.hi[u], b.hi[u], b.lo[u]}, vs[4] = {b.lo[v], b.lo[v], b.hi[v], b.hi[v]};
      for (int k = 0; k < 4; ++k) {
        q[k][a] = (f & 1) ? b.hi[a] : b.lo[a];
        q[k][u] = us[k];
        q[k][v] = vs[k];
      }
      const auto base = static_cast<std::uint32_t>(s.v.size());
      s.v.insert(s.v.end(), q, q + 4);
      s.c.insert(s.c.end(), 4, glm::u8vec4(0));
      s.t.insert(s.t.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
    }
  }
  return s;
}

double drawn_box_area(const TerrainTree& tree, const Frame& f) {
  double area = 0.0;
  for (std::size_t t = 0; t < f.level.size(); ++t) {
    if (f.level[t] != kBoxLevel) continue;
    area += test::polygon_area({frame_vertex(tree, f, f.indices[3 * t]), frame_vertex(tree, f, f.indices[3 * t + 1]),
                                frame_vertex(tree, f, f.indices[3 * t + 2])});
  }
  return area;
}

TEST(ColorBoxes, OneBoxAboveFlatGroundIsDrawnAfterTheTerrainAsItsThreeFrontFaces) {
  TestWindow w(4, [](int, int) { return 10.0f; });
  const TerrainTree tree(w.view(), 3);
  ColorBox box;
  box.lo = {100.0f, 100.0f, 50.0f};
  box.hi = {200.0f, 250.0f, 90.0f};
  for (int f = 0; f < 6; ++f) box.rgba[static_cast<std::size_t>(f)] = glm::u8vec4(10 * f, 0, 0, 100);
  const Camera c = camera_at({-100.0, -200.0, 500.0}, {1.0, 1.0, -0.8});
  TraversalOptions o;
  o.full_res = true;
  Frame f;
  tree.traverse(c, o, f, std::span(&box, 1));
  // The faces at x = lo, y = lo and z = hi face the eye: 3 quads, 12 vertices, 6 triangles,
  // all after the 32 terrain triangles.
  ASSERT_EQ(std::count(f.level.begin(), f.level.end(), kBoxLevel), 6);
  EXPECT_EQ(f.transient_positions.size(), 12u);
  EXPECT_EQ(f.transient_base, tree.positions().size());
  for (std::size_t t = f.level.size() - 6; t < f.level.size(); ++t) EXPECT_EQ(f.level[t], kBoxLevel);
  std::vector<int> colours;
  for (const glm::u8vec4& c4 : f.transient_colors) colours.push_back(c4.r / 10);
  std::sort(colours.begin(), colours.end());
  colours.erase(std::unique(colours.begin(), colours.end()), colours.end());
  EXPECT_EQ(colours, (std::vector<int>{0, 2, 5})) << "faces -x, -y and +z";
  EXPECT_EQ(f.boxes.boxes, 1u);
  EXPECT_EQ(f.boxes.faces, 3u);
}

TEST(ColorBoxes, BoxesOnlyInsertFacesIntoTheOrderOfEverythingElse) {
  std::mt19937 rng(5);
  TestWindow w(16, [](int, int) { return 0.0f; });
  TerrainTree tree = hilly_tree(rng, w);
  const test::TriangleSoup soup = soup_of(rng, 30);
  tree.merge(soup.v, soup.c, soup.t);
  std::uniform_real_distribution<double> xy(-300.0, 1900.0), z(420.0, 900.0), dir(-1.0, 1.0);
  Frame with, without;
  for (int trial = 0; trial < 12; ++trial) {
    const glm::dvec3 eye(xy(rng), xy(rng), z(rng));
    const Camera c = camera_at(eye, {dir(rng), dir(rng), -0.5});
    const std::vector<ColorBox> boxes = grid_boxes(eye, 9, 7, 5, {-150.0, -100.0, 50.0}, {1750.0, 1700.0, 600.0}, rng);
    TraversalOptions o;
    o.cull = false;  // a small BSP holding boxes is drawn without leaving out subtrees
    o.threshold_px = 1.0f + static_cast<float>(trial % 4);
    tree.traverse(c, o, without);
    tree.traverse(c, o, with, boxes);
    std::vector<std::uint32_t> rest;
    for (std::size_t t = 0; t < with.level.size(); ++t)
      if (with.level[t] != kBoxLevel) rest.insert(rest.end(), with.indices.begin() + 3 * t, with.indices.begin() + 3 * t + 3);
    EXPECT_EQ(rest, without.indices) << "trial " << trial;
    EXPECT_GT(with.level.size(), without.level.size());
  }
}

TEST(ColorBoxes, FacesAreInBackToFrontOrderWithTerrainAndMergedPiecesFromRandomEyes) {
  std::mt19937 rng(77);
  TestWindow w(16, [](int, int) { return 0.0f; });
  TerrainTree tree = hilly_tree(rng, w);
  const test::TriangleSoup soup = soup_of(rng, 24);
  tree.merge(soup.v, soup.c, soup.t);
  std::uniform_real_distribution<double> xy(-300.0, 1900.0), z(-100.0, 900.0), dir(-1.0, 1.0);
  Frame f;
  std::size_t faces = 0, bsp_faces = 0;
  for (int trial = 0; trial < 40; ++trial) {
    glm::dvec3 eye(xy(rng), xy(rng), z(rng));
    if (trial % 3 == 0) eye.x = 800.0;  // on the root's split plane
    const Camera c = camera_at(eye, {dir(rng), dir(rng), 0.6 * dir(rng)});
    // Boxes of a few sizes, some reaching beyond the window and below the terrain.
    const int n = 3 + trial % 6;
    const std::vector<ColorBox> boxes = grid_boxes(eye, n + 2, n + 1, n, {-250.0, -150.0, -20.0}, {1850.0, 1750.0, 650.0}, rng);
    TraversalOptions o;
    o.cull = trial % 2 == 0;
    o.threshold_px = 2.0f * static_cast<float>(1 << (trial % 7));
    o.front_to_back = trial % 5 == 4;
    o.occlusion = trial % 4 == 1;
    o.occlusion_adaptive = false;
    tree.traverse(c, o, f, boxes);
    faces += f.boxes.faces;
    bsp_faces += f.boxes.bsp_faces;
    EXPECT_EQ(order_violations(tree, f, eye, 150, rng, !o.front_to_back), 0) << "trial " << trial;
  }
  EXPECT_GT(faces, 0u);
  EXPECT_GT(bsp_faces, 0u) << "some faces went into merged surfaces' small BSPs";
}

// Without culling, each face that faces the eye is drawn exactly where it lies above the
// terrain the frame draws (inside the window; all of it outside), whatever the LOD choice. The
// boxes' faces lie off the lattice's planes: the brute-force reference would count a face
// lying in a cell's boundary plane in both cells.
TEST(ColorBoxes, DrawnFaceAreaIsTheFrontFaceAreaAboveTheDrawnTerrain) {
  std::mt19937 rng(13);
  TestWindow w(16, [](int, int) { return 0.0f; });
  TerrainTree tree = hilly_tree(rng, w);
  const test::TriangleSoup soup = soup_of(rng, 20);
  tree.merge(soup.v, soup.c, soup.t);
  Frame f;
  for (const glm::dvec3 eye : {glm::dvec3(-400.0, -300.0, 700.0), glm::dvec3(900.0, 700.0, 520.0), glm::dvec3(2000.0, 300.0, 450.0)}) {
    const Camera c = camera_at(eye, glm::dvec3(800.0, 800.0, 250.0) - eye);
    const std::vector<ColorBox> boxes = grid_boxes(eye, 8, 6, 5, {-187.0, -113.0, 7.0}, {1789.0, 1711.0, 611.0}, rng);
    const test::TriangleSoup faces = front_faces(boxes, eye);
    for (float t : {0.5f, 4.0f, 64.0f}) {
      TraversalOptions o;
      o.cull = false;
      o.threshold_px = t;
      tree.traverse(c, o, f, boxes);
      const double expected = test::area_above_drawn_terrain(tree, f, faces, 0.0, 1600.0, 0.0, 1600.0);
      EXPECT_GT(expected, 0.0);
      EXPECT_NEAR(drawn_box_area(tree, f), expected, 1e-6 * expected) << "threshold " << t;
    }
  }
}

// With culling (cells out of view keep the boxes of their columns, small BSPs holding boxes are
// drawn whole), the face area drawn inside the view frustum is the faces' area inside it above
// the terrain the same LOD choice draws without culling. (Without crack fills: their balancing
// may refine cells in view next to fine cells out of view, which culling leaves unrefined.)
TEST(ColorBoxes, WithCullingTheDrawnFaceAreaInsideTheFrustumIsTheFaceAreaAboveTheTerrain) {
  std::mt19937 rng(41);
  TestWindow w(16, [](int, int) { return 0.0f; });
  TerrainTree tree = hilly_tree(rng, w);
  const test::TriangleSoup soup = soup_of(rng, 30);
  tree.merge(soup.v, soup.c, soup.t);
  std::uniform_real_distribution<double> xy(-200.0, 1800.0), z(250.0, 700.0), dir(-1.0, 1.0), pitch(-0.8, 0.8);
  Frame f, unculled;
  double seen = 0.0;
  for (int trial = 0; trial < 30; ++trial) {
    const glm::dvec3 eye(xy(rng), xy(rng), z(rng));
    const Camera c = camera_at(eye, {dir(rng), dir(rng), pitch(rng)});
    const std::vector<ColorBox> boxes = grid_boxes(eye, 8, 6, 5, {-187.0, -113.0, 7.0}, {1789.0, 1711.0, 611.0}, rng);
    TraversalOptions o;
    o.threshold_px = 1.0f + static_cast<float>(trial % 5);
    o.crack_fills = false;
    tree.traverse(c, o, f, boxes);
    o.cull = false;
    tree.traverse(c, o, unculled, boxes);
    const auto frustum = test::frustum_of(c);
    const double expected = test::area_above_drawn_terrain(tree, unculled, front_faces(boxes, eye), 0.0, 1600.0, 0.0, 1600.0, frustum);
    double drawn = 0.0;
    for (std::size_t t = 0; t < f.level.size(); ++t) {
      if (f.level[t] != kBoxLevel) continue;
      drawn += test::polygon_area(test::clip_all({frame_vertex(tree, f, f.indices[3 * t]), frame_vertex(tree, f, f.indices[3 * t + 1]),
                                                  frame_vertex(tree, f, f.indices[3 * t + 2])},
                                                 frustum));
    }
    EXPECT_NEAR(drawn, expected, 1e-6 * expected + 1e-3) << "trial " << trial;
    seen += expected;
  }
  EXPECT_GT(seen, 0.0);
}

// A box that lies in no drawn region keeps being drawn where it shows: boxes above culled cells
// (the cells' content boxes are out of view, the boxes above them are not) are in the frame.
TEST(ColorBoxes, BoxesAboveCulledTerrainAreStillDrawn) {
  TestWindow w(16, [](int, int) { return 0.0f; });
  const TerrainTree tree(w.view(), 4);
  // The eye at 1000 m looks level, north: the ground below the view (z 0) is out of view, a
  // box at 950-1050 m ahead is in it.
  const Camera c = camera_at({800.0, -200.0, 1000.0}, {0.0, 1.0, 0.0});
  ColorBox box;
  box.lo = {700.0f, 600.0f, 950.0f};
  box.hi = {900.0f, 800.0f, 1050.0f};
  box.rgba.fill(glm::u8vec4(255, 0, 0, 128));
  Frame f;
  tree.traverse(c, TraversalOptions{}, f, std::span(&box, 1));
  EXPECT_EQ(std::count(f.level.begin(), f.level.end(), kBoxLevel), 2) << "its south face";
}

}  // namespace
}  // namespace terravol::mrbsp
