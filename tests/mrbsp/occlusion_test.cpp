// TraversalOptions::occlusion (Greene 1996): what the coverage pass leaves out is hidden behind
// the terrain it draws, checked by casting rays from the eye by brute force; and the rest is
// what the traversal draws without it, in the same order.
#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cmath>
#include <random>
#include <set>
#include <tuple>

#include "mrbsp/terrain_tree.h"
#include "tree_test_util.h"

namespace terravol::mrbsp {
namespace {

using test::TestWindow;

// Rolling ground with two ridges across it (rows 24 and 40 of 64), which hide the valleys
// beyond them from a low eye in the south.
TestWindow ridged() {
  return TestWindow(64, [](int i, int j) {
    const float ridge = 600.0f * std::exp(-0.05f * static_cast<float>((j - 24) * (j - 24))) +
                        800.0f * std::exp(-0.05f * static_cast<float>((j - 40) * (j - 40)));
    return ridge + 30.0f * std::sin(0.3f * static_cast<float>(i)) * std::cos(0.2f * static_cast<float>(j));
  });
}

Camera low_eye(double x, double y, double z, double heading_x, double pitch) {
  return test::looking({x, y, z}, {heading_x, 1.0, pitch}, 50.0, 400, 240, 1.0);
}

using Tri = std::tuple<std::uint32_t, std::uint32_t, std::uint32_t>;

std::vector<Tri> triangles_of(const Frame& f) {
  std::vector<Tri> out;
  for (std::size_t t = 0; t < f.level.size(); ++t) out.emplace_back(f.indices[3 * t], f.indices[3 * t + 1], f.indices[3 * t + 2]);
  return out;
}

TEST(Occlusion, LeavesOutOnlyTerrainHiddenBehindWhatItDrawsAndKeepsTheOrder) {
  const TestWindow w = ridged();
  const TerrainTree tree(w.view(), 5);
  const auto& p = tree.positions();
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> x(600.0, 5800.0), y(200.0, 1400.0), z(80.0, 400.0), hx(-0.5, 0.5),
      pitch(-0.15, 0.05);
  std::size_t culled_total = 0;
  for (int trial = 0; trial < 12; ++trial) {
    const Camera c = low_eye(x(rng), y(rng), z(rng), hx(rng), pitch(rng));
    TraversalOptions o;
    o.threshold_px = 1.0f + static_cast<float>(trial % 3);
    Frame all, kept;
    tree.traverse(c, o, all);
    o.occlusion = true;
    tree.traverse(c, o, kept);
    culled_total += kept.occlusion.culled_leaves;
    EXPECT_GT(kept.occlusion.tested_nodes + kept.occlusion.sampled_visible, 0u);
    // The kept triangles come in the same order as without occlusion.
    const std::vector<Tri> a = triangles_of(all), k = triangles_of(kept);
    std::size_t q = 0;
    for (const Tri& t : a) {
      if (q < k.size() && t == k[q]) ++q;
    }
    EXPECT_EQ(q, k.size()) << "trial " << trial << ": the kept triangles are a subsequence of all";
    // Every point well inside a left-out triangle, in view, is hidden by a kept one nearer.
    const std::set<Tri> kept_set(k.begin(), k.end());
    const auto frustum = test::frustum_of(c);
    int unchecked = 0;
    for (const Tri& t : a) {
      if (kept_set.count(t)) continue;
      const glm::dvec3 v0(p[std::get<0>(t)]), v1(p[std::get<1>(t)]), v2(p[std::get<2>(t)]);
      for (const glm::dvec3 bary : {glm::dvec3(1, 1, 1) / 3.0, glm::dvec3(0.6, 0.2, 0.2), glm::dvec3(0.2, 0.6, 0.2), glm::dvec3(0.2, 0.2, 0.6)}) {
        const glm::dvec3 point = bary.x * v0 + bary.y * v1 + bary.z * v2;
        bool inside = true;
        for (const auto& pl : frustum) inside = inside && glm::dot(pl.n, point) + pl.d > 0.0;
        if (!inside) continue;
        const glm::dvec3 d = point - c.eye;
        const double dist = glm::length(d);
        bool hidden = false;
        for (const Tri& o2 : k) {
          const double h = test::ray_triangle(c.eye, d / dist, glm::dvec3(p[std::get<0>(o2)]), glm::dvec3(p[std::get<1>(o2)]),
                                              glm::dvec3(p[std::get<2>(o2)]));
          if (h > 0.0 && h < dist * (1.0 - 1e-6)) {
            hidden = true;
            break;
          }
        }
        EXPECT_TRUE(hidden) << "trial " << trial << ": a visible point of a left-out triangle";
        if (!hidden && ++unchecked > 3) return;
      }
    }
  }
  EXPECT_GT(culled_total, 50u) << "the ridges must hide cells for the test to mean anything";
}

// Straight down from 20 km over the ridged window's centre: nothing is hidden.
Camera from_above() {
  Camera c;
  c.eye = {3200.0, 3200.0, 20000.0};
  c.forward = {0.0, 0.0, -1.0};
  c.up = {0.0, 1.0, 0.0};
  c.width = 400;
  c.height = 240;
  return c;
}

TEST(Occlusion, AnOverviewFromAboveCullsNothing) {
  const TestWindow w = ridged();
  const TerrainTree tree(w.view(), 5);
  const Camera c = from_above();
  TraversalOptions o;
  o.occlusion = true;
  Frame f;
  tree.traverse(c, o, f);
  EXPECT_GT(f.occlusion.tested_nodes + f.occlusion.sampled_visible, 0u);
  EXPECT_EQ(f.occlusion.culled_nodes, 0u);
  EXPECT_GT(f.leaves, 0u);
}

// A pass that culls fewer cells than it keeps is left out of the next 8 traversals with the
// same Frame (they draw what the unculled traversal draws), then tried again; one that pays
// runs every time.
TEST(Occlusion, APassThatDoesNotPayIsLeftOutOfTheNextEightFramesThenTriedAgain) {
  const TestWindow w = ridged();
  const TerrainTree tree(w.view(), 5);
  const Camera above = from_above();
  TraversalOptions o;
  Frame unculled, f;
  tree.traverse(above, o, unculled);
  o.occlusion = true;
  for (int k = 0; k < 10; ++k) {
    tree.traverse(above, o, f);
    const bool probe = k == 0 || k == 9;
    EXPECT_EQ(f.occlusion.ran, probe) << "traversal " << k;
    EXPECT_EQ(f.occlusion.left_out, !probe) << "traversal " << k;
    EXPECT_EQ(f.indices, unculled.indices) << "traversal " << k;
  }
  // Not adaptive: the pass runs every time.
  o.occlusion_adaptive = false;
  for (int k = 0; k < 3; ++k) {
    tree.traverse(above, o, f);
    EXPECT_TRUE(f.occlusion.ran);
  }
  // Low among the ridges, where most is hidden, it runs in every traversal.
  o.occlusion_adaptive = true;
  const Camera low = low_eye(3000.0, 600.0, 150.0, 0.0, -0.05);
  Frame g;
  std::size_t ran = 0;
  for (int k = 0; k < 10; ++k) {
    tree.traverse(low, o, g);
    ran += g.occlusion.ran ? 1 : 0;
  }
  ASSERT_GT(g.occlusion.culled_leaves, g.leaves) << "the view must be mostly hidden for the test to mean anything";
  EXPECT_EQ(ran, 10u);
}

// Over a flight, hierarchy updating and its conservative form test fewer cells than testing
// every one, and never leave out a triangle the frame-by-frame pass keeps (what they draw lies
// between that and everything).
TEST(Occlusion, CoherenceTestsFewerCellsAndKeepsEverythingVisible) {
  const TestWindow w = ridged();
  const TerrainTree tree(w.view(), 5);
  Frame plain, updated, conservative;
  std::size_t tests[3] = {0, 0, 0}, skipped = 0;
  for (int k = 0; k < 60; ++k) {
    const Camera c = low_eye(2000.0 + 25.0 * k, 600.0 + 10.0 * k, 250.0, 0.2 - 0.004 * k, -0.05);
    TraversalOptions o;
    o.occlusion = true;
    o.occlusion_adaptive = false;  // every frame's pass, so that the modes compare
    tree.traverse(c, o, plain);
    o.coherence = Coherence::kUpdate;
    tree.traverse(c, o, updated);
    o.coherence = Coherence::kConservative;
    o.p_skip = 0.5;
    tree.traverse(c, o, conservative);
    tests[0] += plain.occlusion.tested_nodes + plain.occlusion.sampled_visible;
    tests[1] += updated.occlusion.tested_nodes + updated.occlusion.sampled_visible;
    tests[2] += conservative.occlusion.tested_nodes + conservative.occlusion.sampled_visible;
    skipped += updated.occlusion.skipped_tests;
    const std::vector<Tri> p = triangles_of(plain);
    const std::set<Tri> ps(p.begin(), p.end());
    for (const Frame* f : {&updated, &conservative}) {
      const std::vector<Tri> t = triangles_of(*f);
      const std::set<Tri> ts(t.begin(), t.end());
      EXPECT_TRUE(std::includes(ts.begin(), ts.end(), ps.begin(), ps.end())) << "frame " << k;
    }
  }
  EXPECT_GT(skipped, 0u);
  EXPECT_LT(tests[1], tests[0]);
  EXPECT_LT(tests[2], tests[1]);
  std::printf("tests over the flight: every cell %zu, updating %zu (%.0f%%), conservative %zu (%.0f%%)\n", tests[0], tests[1],
              100.0 * tests[1] / tests[0], tests[2], 100.0 * tests[2] / tests[0]);
}

}  // namespace
}  // namespace terravol::mrbsp
