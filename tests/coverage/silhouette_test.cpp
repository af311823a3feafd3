#include "coverage/silhouette.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>
#include <vector>

#include <glm/ext/matrix_clip_space.hpp>
#include <glm/ext/matrix_transform.hpp>
#include <glm/mat4x4.hpp>

#include "brute_force.h"
#include "coverage/pyramid.h"

namespace terravol::coverage {
namespace {

using test::Fx;

TEST(ProjectToWindow, MapsClipCoordinatesToGlWindowCoordinates) {
  const std::array<glm::dvec4, 3> clip{glm::dvec4(0, 0, 0, 1), glm::dvec4(-2, -2, 0, 2), glm::dvec4(3, -3, 1, 3)};
  std::array<glm::dvec2, 3> win;
  ASSERT_TRUE(project_to_window(clip, 1280, 720, win));
  EXPECT_EQ(win[0], glm::dvec2(640, 360));
  EXPECT_EQ(win[1], glm::dvec2(0, 0));      // NDC (-1, -1): the bottom-left corner
  EXPECT_EQ(win[2], glm::dvec2(1280, 0));   // NDC (1, -1)
}

TEST(ProjectToWindow, RefusesPointsAtOrBehindTheEye) {
  std::array<glm::dvec2, 2> win{glm::dvec2(7, 7), glm::dvec2(7, 7)};
  EXPECT_FALSE(project_to_window(std::array{glm::dvec4(0, 0, 0, 1), glm::dvec4(0, 0, 0, 0)}, 100, 100, win));
  EXPECT_FALSE(project_to_window(std::array{glm::dvec4(0, 0, 0, 1), glm::dvec4(1, 1, -3, -0.5)}, 100, 100, win));
  EXPECT_FALSE(project_to_window(std::array{glm::dvec4(0, NAN, 0, 1), glm::dvec4(0, 0, 0, 1)}, 100, 100, win));
  EXPECT_EQ(win[0], glm::dvec2(7, 7));  // nothing written
}

TEST(ConvexHull, SquareWithInteriorAndCollinearPointsKeepsTheFourCorners) {
  const std::vector<glm::dvec2> pts{{1, 1}, {5, 5}, {3, 3}, {5, 1}, {1, 5}, {3, 1}, {1, 1}, {2, 4}};
  std::vector<glm::dvec2> h(pts.size());
  ASSERT_EQ(convex_hull(pts, h), 4);
  EXPECT_EQ(h[0], glm::dvec2(1, 1));  // counterclockwise from the lowest-leftmost
  EXPECT_EQ(h[1], glm::dvec2(5, 1));
  EXPECT_EQ(h[2], glm::dvec2(5, 5));
  EXPECT_EQ(h[3], glm::dvec2(1, 5));
  EXPECT_EQ(convex_hull(std::vector<glm::dvec2>{{2, 2}, {2, 2}}, h), 1);
  EXPECT_EQ(convex_hull(std::vector<glm::dvec2>{{0, 0}, {2, 2}, {1, 1}, {3, 3}}, h), 2);
  EXPECT_EQ(h[1], glm::dvec2(3, 3));
  EXPECT_EQ(convex_hull(std::vector<glm::dvec2>{}, h), 0);
  EXPECT_THROW(convex_hull(std::vector<glm::dvec2>(65, glm::dvec2(0)), h), std::invalid_argument);
  EXPECT_THROW(convex_hull(std::vector<glm::dvec2>{{NAN, 0}}, h), std::invalid_argument);
}

TEST(ConvexHull, RandomPointSetsMatchGiftWrapping) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-50.0, 50.0);
  std::uniform_int_distribution<int> small(-3, 3), count(1, 12);
  for (int trial = 0; trial < 2000; ++trial) {
    std::vector<glm::dvec2> pts;
    const int n = count(rng);
    for (int i = 0; i < n; ++i) pts.push_back(trial % 2 ? glm::dvec2(u(rng), u(rng)) : glm::dvec2(small(rng), small(rng)));
    std::vector<glm::dvec2> h(pts.size());
    h.resize(static_cast<std::size_t>(convex_hull(pts, h)));
    std::vector<Fx> fx;
    for (const glm::dvec2& p : pts) fx.push_back(test::snap_ref(p));
    const std::vector<Fx> want = test::hull_ref(fx);
    ASSERT_EQ(h.size(), want.size()) << trial;
    for (std::size_t i = 0; i < h.size(); ++i) {  // both start at the lowest-leftmost point
      ASSERT_EQ(test::snap_ref(h[i]).x, want[i].x) << trial;
      ASSERT_EQ(test::snap_ref(h[i]).y, want[i].y) << trial;
      ASSERT_EQ(h[i] * 256.0, glm::round(h[i] * 256.0));  // the snapped points themselves
    }
  }
}

// A box's eight corners through a real perspective projection: hidden() of the corners and of
// their hull answer alike, and a box in front of a covered wall is hidden only when its
// silhouette lies within the wall.
TEST(ConvexHull, ProjectedBoxCornersAndTheirHullAreTestedAlike) {
  const glm::dmat4 proj = glm::perspective(glm::radians(45.0), 1280.0 / 720.0, 1.0, 1e5);
  const glm::dmat4 view = glm::lookAt(glm::dvec3(0, 0, 0), glm::dvec3(0, 1, 0), glm::dvec3(0, 0, 1));
  Pyramid p(1280, 720);
  p.cover(std::vector<glm::dvec2>{{0, 0}, {1280, 0}, {1280, 400}, {0, 400}}, 0.0);  // the lower part
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int hidden = 0, visible = 0;
  for (int trial = 0; trial < 500; ++trial) {
    const glm::dvec3 c(40 * u(rng), 100 + 50 * u(rng), 30 * u(rng) - 5), half(3 + 2 * u(rng), 3 + 2 * u(rng), 1 + u(rng));
    std::array<glm::dvec4, 8> clip;
    for (int i = 0; i < 8; ++i) {
      const glm::dvec3 corner = c + half * glm::dvec3(i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1);
      clip[static_cast<std::size_t>(i)] = proj * view * glm::dvec4(corner, 1.0);
    }
    std::array<glm::dvec2, 8> win, hull;
    ASSERT_TRUE(project_to_window(clip, 1280, 720, win));
    const int n = convex_hull(win, hull);
    ASSERT_GE(n, 4);
    const bool a = p.hidden(win, 0.5), b = p.hidden(std::span(hull.data(), static_cast<std::size_t>(n)), 0.5);
    ASSERT_EQ(a, b) << trial;
    double top = -1e300;
    for (const glm::dvec2& w : win) top = std::max(top, w.y);
    if (top < 399.0) {
      ASSERT_TRUE(a) << trial;
    }
    if (top > 400.0) {
      ASSERT_FALSE(a) << trial;
    }
    (a ? hidden : visible)++;
  }
  EXPECT_GT(hidden, 50);
  EXPECT_GT(visible, 50);
}

}  // namespace
}  // namespace terravol::coverage
