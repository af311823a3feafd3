#include "coverage/pyramid.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "brute_force.h"

namespace terravol::coverage {
namespace {

using test::Bitmap;
using test::claimed_ref;
using test::hidden_ref;
using Poly = std::vector<glm::dvec2>;

// Compares every pixel of the pyramid with a reference bitmap; returns the first difference.
std::string differences(const Pyramid& p, const Bitmap& want) {
  for (int y = 0; y < want.h; ++y) {
    for (int x = 0; x < want.w; ++x) {
      if (p.covered(x, y) != static_cast<bool>(want.at(x, y))) {
        return "pixel (" + std::to_string(x) + ", " + std::to_string(y) + ") is " + (p.covered(x, y) ? "covered" : "vacant") +
               ", brute force says " + (want.at(x, y) ? "covered" : "vacant");
      }
    }
  }
  return {};
}

void merge(Bitmap& into, const Bitmap& from) {
  for (std::size_t i = 0; i < into.bits.size(); ++i) into.bits[i] |= from.bits[i];
}

Poly rect(double x0, double y0, double x1, double y1) { return {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}; }

// Random convex polygons of every kind the tiler must get exactly right.
Poly random_polygon(std::mt19937& rng, int w, int h) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const auto in_view = [&](double slack) { return glm::dvec2((u(rng) * (1 + 2 * slack) - slack) * w, (u(rng) * (1 + 2 * slack) - slack) * h); };
  const auto scale = [&] { return std::pow(10.0, u(rng) * 3.5 - 0.5); };  // 0.3 px to 1000 px
  Poly p;
  switch (std::uniform_int_distribution<int>(0, 7)(rng)) {
    case 0: {  // a triangle of any size
      const glm::dvec2 c = in_view(0.1);
      const double s = scale();
      for (int i = 0; i < 3; ++i) p.push_back(c + s * glm::dvec2(u(rng) - 0.5, u(rng) - 0.5));
      break;
    }
    case 1: {  // a convex polygon on an ellipse, 3 to 12 vertices
      const glm::dvec2 c = in_view(0.2);
      const double rx = scale(), ry = scale() * (0.2 + u(rng));
      const int n = std::uniform_int_distribution<int>(3, 12)(rng);
      std::vector<double> t;
      for (int i = 0; i < n; ++i) t.push_back(u(rng) * 2 * std::numbers::pi);
      std::sort(t.begin(), t.end());
      for (double a : t) p.push_back(c + glm::dvec2(rx * std::cos(a), ry * std::sin(a)));
      break;
    }
    case 2: {  // a sliver
      const glm::dvec2 a = in_view(0.1), b = a + scale() * glm::dvec2(u(rng) - 0.5, u(rng) - 0.5);
      const glm::dvec2 d = b - a;
      p = {a, b, b + (u(rng) * 0.05) * glm::dvec2(-d.y, d.x) + glm::dvec2(0.01, 0.0)};
      break;
    }
    case 3: {  // vertices exactly on pixel centres
      std::uniform_int_distribution<int> xi(-3, w + 3), yi(-3, h + 3), di(-12, 12);
      const glm::dvec2 a(xi(rng) + 0.5, yi(rng) + 0.5);
      p = {a, a + glm::dvec2(di(rng), di(rng)), a + glm::dvec2(di(rng), di(rng))};
      if (u(rng) < 0.5) p.push_back(p[2] + glm::dvec2(di(rng), di(rng)));
      break;
    }
    case 4: {  // vertices on tile boundaries (multiples of 8 px) and on pixel corners
      std::uniform_int_distribution<int> ti(-1, w / 8 + 1), tj(-1, h / 8 + 1), k(-2, 2);
      const glm::dvec2 a(8.0 * ti(rng), 8.0 * tj(rng));
      p = {a, a + 8.0 * glm::dvec2(k(rng), k(rng)), a + glm::dvec2(8 * k(rng) + k(rng), 8 * k(rng) + k(rng))};
      break;
    }
    case 5: {  // huge, reaching far beyond the viewport
      const double s = std::pow(10.0, 3.0 + 3.0 * u(rng));
      const glm::dvec2 c = in_view(0.0);
      for (int i = 0; i < 3; ++i) {
        const double a = u(rng) * 2 * std::numbers::pi;
        p.push_back(c + s * glm::dvec2(std::cos(a), std::sin(a)));
      }
      break;
    }
    case 6: {  // axis-aligned rectangles, corners anywhere
      const glm::dvec2 a = in_view(0.3), b = in_view(0.3);
      p = rect(std::min(a.x, b.x), std::min(a.y, b.y), std::max(a.x, b.x), std::max(a.y, b.y));
      break;
    }
    default: {  // partly off screen, straddling a border or a corner
      const glm::dvec2 c(u(rng) < 0.5 ? 0.0 : w, u(rng) < 0.5 ? u(rng) * h : (u(rng) < 0.5 ? 0.0 : h));
      const double s = scale() * 2;
      for (int i = 0; i < 3; ++i) p.push_back(c + s * glm::dvec2(u(rng) - 0.5, u(rng) - 0.5));
      break;
    }
  }
  if (u(rng) < 0.5) std::reverse(p.begin(), p.end());
  return p;
}

double random_margin(std::mt19937& rng) {
  static const double kMargins[] = {0.0, 0.0, 1.0 / 256.0, 0.1, 0.5, 1.0, 2.3, 7.0};
  return kMargins[std::uniform_int_distribution<int>(0, 7)(rng)];
}

TEST(Pyramid, ShapeAt1280x720IsTilesThenTwentyByTwelveThenThreeByTwoThenRoot) {
  const Pyramid p(1280, 720);
  ASSERT_EQ(p.triage_levels(), 3);
  EXPECT_EQ(p.grid_width(0), 160);
  EXPECT_EQ(p.grid_height(0), 90);
  EXPECT_EQ(p.grid_width(1), 20);
  EXPECT_EQ(p.grid_height(1), 12);
  EXPECT_EQ(p.grid_width(2), 3);
  EXPECT_EQ(p.grid_height(2), 2);
  EXPECT_EQ(p.grid_width(3), 1);
  EXPECT_EQ(p.grid_height(3), 1);
  EXPECT_EQ(p.check_invariants(), "");
  EXPECT_FALSE(p.full());
  EXPECT_EQ(p.covered_count(), 0u);
}

TEST(Pyramid, ShapeOfTinyAndHugeViewports) {
  const Pyramid one(1, 1);
  EXPECT_EQ(one.triage_levels(), 1);
  EXPECT_EQ(one.check_invariants(), "");
  const Pyramid huge(16384, 9);
  EXPECT_EQ(huge.triage_levels(), 4);  // 2048 tiles, 256, 32, 4, 1
  EXPECT_EQ(huge.grid_width(3), 4);
  EXPECT_EQ(huge.check_invariants(), "");
}

TEST(Pyramid, RejectsViewportsOutsideTheRange) {
  EXPECT_THROW(Pyramid(0, 10), std::invalid_argument);
  EXPECT_THROW(Pyramid(10, 16385), std::invalid_argument);
  EXPECT_THROW(Pyramid(-1, -1), std::invalid_argument);
}

TEST(Cover, AxisAlignedSquareClaimsTheCentresInside) {
  Pyramid p(32, 16);
  p.cover(rect(2, 3, 6, 5), 0.0);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 32; ++x) EXPECT_EQ(p.covered(x, y), x >= 2 && x <= 5 && y >= 3 && y <= 4) << x << ", " << y;
  EXPECT_EQ(p.covered_count(), 8u);
  EXPECT_EQ(p.stats().pixels_claimed, 8u);
  EXPECT_EQ(p.check_invariants(), "");
}

TEST(Cover, CentresOnEdgesFollowTheBottomLeftFillRule) {
  // Edges through pixel centres: the left (interior at +x) and bottom (interior at +y) edges
  // own them, the right and top ones do not.
  Pyramid p(16, 16);
  p.cover(rect(2.5, 3.5, 6.5, 5.5), 0.0);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) EXPECT_EQ(p.covered(x, y), x >= 2 && x <= 5 && y >= 3 && y <= 4) << x << ", " << y;
  // The same square clockwise claims the same.
  Pyramid q(16, 16);
  q.cover(Poly{{2.5, 3.5}, {2.5, 5.5}, {6.5, 5.5}, {6.5, 3.5}}, 0.0);
  EXPECT_EQ(q.covered_count(), 8u);
  EXPECT_TRUE(q.covered(2, 3));
  EXPECT_FALSE(q.covered(6, 3));
  EXPECT_FALSE(q.covered(2, 5));
}

TEST(Cover, TwoTrianglesSharingADiagonalClaimEachCentreOnItOnce) {
  // The diagonal from (0.5, 0.5) to (8.5, 8.5) passes through 9 pixel centres.
  const Poly lower{{0.5, 0.5}, {8.5, 0.5}, {8.5, 8.5}}, upper{{0.5, 0.5}, {8.5, 8.5}, {0.5, 8.5}};
  Pyramid a(16, 16), b(16, 16), both(16, 16);
  a.cover(lower, 0.0);
  b.cover(upper, 0.0);
  both.cover(lower, 0.0);
  both.cover(upper, 0.0);
  for (int y = 0; y < 16; ++y) {
    for (int x = 0; x < 16; ++x) {
      EXPECT_FALSE(a.covered(x, y) && b.covered(x, y)) << x << ", " << y;
      EXPECT_EQ(both.covered(x, y), x <= 7 && y <= 7) << x << ", " << y;
    }
  }
  // The diagonal's centres: the lower triangle's hypotenuse has its interior at +x (owns them).
  for (int i = 0; i < 8; ++i) EXPECT_TRUE(a.covered(i, i)) << i;
  EXPECT_EQ(a.covered_count() + b.covered_count(), 64u);
}

TEST(Cover, MarginErodesEveryEdge) {
  Pyramid p(16, 16);
  p.cover(rect(0, 0, 10, 10), 2.0);  // centres more than 2 px inside: 2.5 .. 7.5
  EXPECT_EQ(p.covered_count(), 36u);
  EXPECT_TRUE(p.covered(2, 2));
  EXPECT_TRUE(p.covered(7, 7));
  EXPECT_FALSE(p.covered(1, 5));
  EXPECT_FALSE(p.covered(8, 5));
  Pyramid q(16, 16);
  q.cover(rect(0, 0, 10, 10), 1.5);  // exactly 1.5 px inside: owned on the left and bottom
  EXPECT_EQ(q.covered_count(), 49u);
  EXPECT_TRUE(q.covered(1, 1));
  EXPECT_FALSE(q.covered(8, 1));
  EXPECT_FALSE(q.covered(1, 8));
  // A triangle whose inscribed circle is smaller than the margin claims nothing.
  Pyramid r(16, 16);
  r.cover(Poly{{1, 1}, {5, 1}, {1, 5}}, 1.2);
  EXPECT_EQ(r.covered_count(), 0u);
}

TEST(Cover, PolygonOutsideTheViewportClaimsNothing) {
  Pyramid p(64, 48);
  p.cover(rect(-30, 10, -1, 20), 0.0);
  p.cover(rect(10, 48, 20, 70), 0.0);
  p.cover(Poly{{64, 0}, {100, 0}, {100, 48}}, 0.0);
  EXPECT_EQ(p.covered_count(), 0u);
  EXPECT_EQ(p.check_invariants(), "");
}

TEST(Cover, ViewportFillingTriangleMakesThePyramidFull) {
  Pyramid p(1280, 720);
  p.cover(Poly{{-1e5, -1e5}, {1e5, -1e5}, {0, 1e5}}, 1.0);
  EXPECT_TRUE(p.full());
  EXPECT_EQ(p.covered_count(), 1280u * 720u);
  EXPECT_EQ(p.stats().pixels_claimed, 1280u * 720u);
  EXPECT_EQ(p.check_invariants(), "");
  // Below the root the work is filling, not visiting: the cells composited are the root and
  // the cells already partly covered, by the pixels beyond the viewport: 4 of the 3x2 level-2
  // cells and the 20 level-1 cells of the top row (tile rows 88..95, of which 90..95 are
  // beyond the 720 px).
  EXPECT_EQ(p.stats().cells_visited, 25u);
  p.cover(rect(10, 10, 500, 500), 0.0);
  EXPECT_EQ(p.stats().pixels_claimed, 1280u * 720u);
}

TEST(Cover, DegenerateAndNonFinitePolygonsClaimNothing) {
  Pyramid p(32, 32);
  p.cover(Poly{{1, 1}, {20, 20}, {10, 10}}, 0.0);          // collinear
  p.cover(Poly{{1, 1}, {20, 1}}, 0.0);                     // two vertices
  p.cover(Poly{{5, 5}, {5, 5}, {5, 5}, {5, 5}}, 0.0);     // one point
  p.cover(Poly{{1, 1}, {20, 1}, {std::numeric_limits<double>::quiet_NaN(), 10}}, 0.0);
  p.cover(Poly{{1, 1}, {20, 1}, {10, std::numeric_limits<double>::infinity()}}, 0.0);
  p.cover(Poly{{-1e9, -1e9}, {1e9, -1e9}, {0, 1e9}}, 0.0);  // beyond kMaxCoordinate
  EXPECT_EQ(p.covered_count(), 0u);
  // Repeated vertices are not edges.
  p.cover(Poly{{0, 0}, {8, 0}, {8, 0}, {8, 8}, {0, 8}, {0, 0}}, 0.0);
  EXPECT_EQ(p.covered_count(), 64u);
}

TEST(Cover, RejectsBadMarginsAndTooManyVertices) {
  Pyramid p(8, 8);
  const Poly t{{0, 0}, {8, 0}, {0, 8}};
  EXPECT_THROW(p.cover(t, -0.5), std::invalid_argument);
  EXPECT_THROW(p.cover(t, std::numeric_limits<double>::quiet_NaN()), std::invalid_argument);
  EXPECT_THROW(p.cover(t, 300.0), std::invalid_argument);
  EXPECT_THROW(p.cover(Poly(65, glm::dvec2(1.0)), 0.0), std::invalid_argument);
  EXPECT_THROW(p.hidden(t, -1.0), std::invalid_argument);
  EXPECT_THROW(p.hidden(Poly(65, glm::dvec2(1.0)), 0.0), std::invalid_argument);
}

// Every kind of polygon on viewports that exercise partial tiles and cells, each tiled into an
// empty pyramid: exactly the brute-force pixels.
TEST(Cover, RandomConvexPolygonsClaimExactlyTheBruteForcePixels) {
  std::mt19937 rng(20240611);
  const int sizes[][2] = {{157, 93}, {64, 64}, {1, 1}, {9, 300}, {513, 70}, {200, 8}};
  for (const auto& wh : sizes) {
    const int w = wh[0], h = wh[1];
    Pyramid p(w, h);
    for (int trial = 0; trial < 300; ++trial) {
      const Poly poly = random_polygon(rng, w, h);
      const double margin = random_margin(rng);
      p.clear();
      p.cover(poly, margin);
      const Bitmap want = claimed_ref(poly, margin, w, h);
      const std::string diff = differences(p, want);
      ASSERT_EQ(diff, "") << w << "x" << h << " trial " << trial << " margin " << margin;
      ASSERT_EQ(p.stats().pixels_claimed, want.count());
      ASSERT_EQ(p.check_invariants(), "") << trial;
    }
  }
}

// Covers accumulate: after each one the pyramid holds the union of the brute-force sets, the
// counters agree, and every triage mask agrees with the finest level.
TEST(Cover, SequencesOfCoversKeepTheTriageMasksConsistent) {
  std::mt19937 rng(77);
  const int sizes[][2] = {{1280, 720}, {130, 77}, {600, 520}};
  for (const auto& wh : sizes) {
    const int w = wh[0], h = wh[1];
    Pyramid p(w, h);
    Bitmap want(w, h);
    const int steps = w > 1000 ? 60 : 150;
    for (int step = 0; step < steps; ++step) {
      const Poly poly = random_polygon(rng, w, h);
      const double margin = random_margin(rng);
      p.cover(poly, margin);
      merge(want, claimed_ref(poly, margin, w, h));
      ASSERT_EQ(p.check_invariants(), "") << w << "x" << h << " step " << step;
      if (step % 10 == 9 || w < 1000) {
        ASSERT_EQ(differences(p, want), "") << w << "x" << h << " step " << step;
      }
      ASSERT_EQ(p.stats().pixels_claimed, want.count());
      ASSERT_EQ(p.covered_count(), want.count());
      ASSERT_EQ(p.full(), want.count() == static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
    }
  }
}

// A grid of jittered vertices (some on pixel centres, some beyond the viewport), two triangles
// per cell, every triangle in its own orientation.
struct Mesh {
  std::vector<Poly> triangles;
};
Mesh grid_mesh(std::mt19937& rng, int w, int h, int nx, int ny) {
  std::uniform_real_distribution<double> jitter(-0.25, 0.25);  // small enough that no triangle folds over
  std::vector<glm::dvec2> v;
  const double sx = (w + 20.0) / nx, sy = (h + 20.0) / ny;
  for (int j = 0; j <= ny; ++j) {
    for (int i = 0; i <= nx; ++i) {
      glm::dvec2 q(-10.0 + i * sx, -10.0 + j * sy);
      if (i > 0 && i < nx && j > 0 && j < ny) q += glm::dvec2(jitter(rng) * sx, jitter(rng) * sy);
      if ((i + j) % 3 == 0) q = glm::floor(q) + 0.5;  // on a pixel centre
      q = glm::round(q * 256.0) / 256.0;           // already snapped: distances are to these edges
      v.push_back(q);
    }
  }
  Mesh m;
  const auto at = [&](int i, int j) { return v[static_cast<std::size_t>(j) * static_cast<std::size_t>(nx + 1) + static_cast<std::size_t>(i)]; };
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const glm::dvec2 a = at(i, j), b = at(i + 1, j), c = at(i + 1, j + 1), d = at(i, j + 1);
      const bool flip = (i * 7 + j * 3) % 2;
      Poly t1 = flip ? Poly{a, b, d} : Poly{a, b, c}, t2 = flip ? Poly{b, c, d} : Poly{a, c, d};
      if ((i + j) % 2) std::reverse(t2.begin(), t2.end());
      m.triangles.push_back(t1);
      m.triangles.push_back(t2);
    }
  }
  return m;
}

double segment_distance(glm::dvec2 p, glm::dvec2 a, glm::dvec2 b) {
  const glm::dvec2 d = b - a;
  const double t = std::clamp(glm::dot(p - a, d) / glm::dot(d, d), 0.0, 1.0);
  return glm::length(p - (a + t * d));
}

TEST(Cover, TriangulatedGridCoversEveryPixelFartherThanTheMarginFromEveryEdge) {
  std::mt19937 rng(5);
  const int w = 150, h = 110;
  for (double margin : {0.25, 1.0, 2.5}) {
    const Mesh mesh = grid_mesh(rng, w, h, 13, 9);
    Pyramid p(w, h);
    for (const Poly& t : mesh.triangles) p.cover(t, margin);
    ASSERT_EQ(p.check_invariants(), "");
    int must = 0;
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        const glm::dvec2 c(x + 0.5, y + 0.5);
        double nearest = 1e300;
        for (const Poly& t : mesh.triangles) {
          for (int e = 0; e < 3; ++e) nearest = std::min(nearest, segment_distance(c, t[static_cast<std::size_t>(e)], t[static_cast<std::size_t>((e + 1) % 3)]));
        }
        if (nearest > margin + 1e-9) {
          ++must;
          ASSERT_TRUE(p.covered(x, y)) << "margin " << margin << " pixel " << x << ", " << y << " is " << nearest << " px from every edge";
        }
        if (nearest < margin - 1e-9) {
          ASSERT_FALSE(p.covered(x, y)) << "margin " << margin << " pixel " << x << ", " << y;
        }
      }
    }
    EXPECT_GT(must, w * h / 10);
  }
}

TEST(Cover, TriangulatedGridWithoutMarginClaimsEveryCentreExactlyOnce) {
  std::mt19937 rng(6);
  const int w = 70, h = 45;
  const Mesh mesh = grid_mesh(rng, w, h, 9, 6);
  Pyramid all(w, h), one(w, h);
  std::size_t total = 0;
  for (const Poly& t : mesh.triangles) {
    one.clear();
    one.cover(t, 0.0);
    total += one.covered_count();
    all.cover(t, 0.0);
  }
  EXPECT_EQ(total, static_cast<std::size_t>(w) * h);  // no centre twice...
  EXPECT_TRUE(all.full());                            // ...and none missed
  EXPECT_EQ(all.check_invariants(), "");
}

// The pixels of `masks` (runs of tiles) as a bitmap; fails (returns false) when a pixel is
// reported twice, a mask is empty, a run longer than one tile is not of whole tiles, or a pixel
// lies outside the viewport.
bool reported_bitmap(const std::vector<TileMask>& masks, Bitmap& out, std::string& why) {
  for (const TileMask& t : masks) {
    if (t.mask == 0 || t.run < 1 || (t.run > 1 && t.mask != ~std::uint64_t{0})) {
      why = "an empty mask or a bad run at tile (" + std::to_string(t.tx) + ", " + std::to_string(t.ty) + ")";
      return false;
    }
    for (int k = 0; k < t.run; ++k) {
      for (int bit = 0; bit < 64; ++bit) {
        if (!((t.mask >> bit) & 1)) continue;
        const int x = 8 * (t.tx + k) + (bit & 7), y = 8 * t.ty + (bit >> 3);
        if (x < 0 || y < 0 || x >= out.w || y >= out.h) {
          why = "pixel (" + std::to_string(x) + ", " + std::to_string(y) + ") outside the viewport";
          return false;
        }
        if (out.at(x, y)) {
          why = "pixel (" + std::to_string(x) + ", " + std::to_string(y) + ") reported twice";
          return false;
        }
        out.at(x, y) = 1;
      }
    }
  }
  return true;
}

// The pixels of `all` not in `before`.
Bitmap less(Bitmap all, const Bitmap& before) {
  for (std::size_t i = 0; i < all.bits.size(); ++i) all.bits[i] = all.bits[i] && !before.bits[i];
  return all;
}

Bitmap covered_bitmap(const Pyramid& p) {
  Bitmap b(p.width(), p.height());
  for (int y = 0; y < p.height(); ++y)
    for (int x = 0; x < p.width(); ++x) b.at(x, y) = p.covered(x, y) ? 1 : 0;
  return b;
}

// Greene's W masks down to the finest level: a recording cover() reports exactly the pixels it
// newly covers (brute force less what was covered before), each once, over sequences of every
// kind of polygon, and covers just what the plain cover() covers.
TEST(CoverReporting, ReportsExactlyThePixelsEachCoverNewlyClaims) {
  std::mt19937 rng(4242);
  const int sizes[][2] = {{157, 93}, {600, 520}, {64, 64}, {9, 300}};
  for (const auto& wh : sizes) {
    const int w = wh[0], h = wh[1];
    Pyramid p(w, h), plain(w, h);
    for (int step = 0; step < 120; ++step) {
      const Poly poly = random_polygon(rng, w, h);
      const double margin = step % 3 == 0 ? 0.0 : random_margin(rng);
      const Bitmap before = covered_bitmap(p);
      std::vector<TileMask> claimed;
      p.cover(poly, margin, claimed);
      plain.cover(poly, margin);
      Bitmap got(w, h);
      std::string why;
      ASSERT_TRUE(reported_bitmap(claimed, got, why)) << w << "x" << h << " step " << step << ": " << why;
      const Bitmap want = less(claimed_ref(poly, margin, w, h), before);
      ASSERT_EQ(got.bits, want.bits) << w << "x" << h << " step " << step;
      ASSERT_EQ(differences(p, covered_bitmap(plain)), "") << step;
      ASSERT_EQ(p.check_invariants(), "") << step;
    }
  }
}

// vacant(): the pixels a cover would claim now, reported without covering them: the pyramid's
// pixels and triage masks are the same afterwards, whatever was covered before.
TEST(CoverReporting, VacantReportsWhatCoverWouldClaimAndChangesNothing) {
  std::mt19937 rng(99);
  const int sizes[][2] = {{1280, 720}, {130, 77}, {513, 70}};
  for (const auto& wh : sizes) {
    const int w = wh[0], h = wh[1];
    Pyramid p(w, h);
    for (int step = 0; step < 60; ++step) {
      const Poly poly = random_polygon(rng, w, h);
      const double margin = step % 2 == 0 ? 0.0 : random_margin(rng);
      const Bitmap before = covered_bitmap(p);
      std::vector<TileMask> shown;
      p.vacant(poly, margin, shown);
      Bitmap got(w, h);
      std::string why;
      ASSERT_TRUE(reported_bitmap(shown, got, why)) << step << ": " << why;
      ASSERT_EQ(differences(p, before), "") << "vacant() changed the pyramid at step " << step;
      ASSERT_EQ(p.check_invariants(), "") << step;
      const Bitmap want = less(claimed_ref(poly, margin, w, h), before);
      ASSERT_EQ(got.bits, want.bits) << w << "x" << h << " step " << step;
      // Then cover it (most of the time), so that later queries meet partial coverage.
      if (step % 4 != 3) {
        std::vector<TileMask> claimed;
        p.cover(poly, margin, claimed);
        Bitmap again(w, h);
        ASSERT_TRUE(reported_bitmap(claimed, again, why)) << why;
        ASSERT_EQ(again.bits, got.bits) << "cover claimed other pixels than vacant reported, step " << step;
      }
    }
  }
}

// A mesh at margin 0 front to back: the reports of all its triangles partition the viewport.
TEST(CoverReporting, TriangulatedGridReportsEveryPixelExactlyOnce) {
  std::mt19937 rng(8);
  const int w = 300, h = 170;
  const Mesh mesh = grid_mesh(rng, w, h, 11, 7);
  Pyramid p(w, h);
  std::vector<TileMask> claimed;
  for (const Poly& t : mesh.triangles) p.cover(t, 0.0, claimed);
  Bitmap got(w, h);
  std::string why;
  ASSERT_TRUE(reported_bitmap(claimed, got, why)) << why;
  EXPECT_EQ(got.count(), static_cast<std::size_t>(w) * h);
  EXPECT_TRUE(p.full());
}

TEST(Cover, ClearEmptiesThePyramidAndResetsTheCounters) {
  Pyramid p(100, 60);
  p.cover(rect(-5, -5, 200, 200), 0.0);
  ASSERT_TRUE(p.full());
  p.clear();
  EXPECT_FALSE(p.full());
  EXPECT_EQ(p.covered_count(), 0u);
  EXPECT_EQ(p.stats().cover_calls, 0u);
  EXPECT_EQ(p.stats().pixels_claimed, 0u);
  EXPECT_EQ(p.check_invariants(), "");
  p.cover(rect(0, 0, 8, 8), 0.0);
  EXPECT_EQ(p.covered_count(), 64u);
}

TEST(Hidden, InsideACoveredSquareIsHidden) {
  Pyramid p(64, 64);
  p.cover(rect(0, 0, 16, 16), 0.0);
  EXPECT_TRUE(p.hidden(rect(4, 4, 12, 12), 0.0));
  EXPECT_TRUE(p.hidden(rect(4, 4, 12, 12), 4.0));    // reaches centres 3.5 px out, all covered
  EXPECT_FALSE(p.hidden(rect(4, 4, 12, 12), 4.6));   // (16, 8) is 4.5 px out, vacant
  EXPECT_FALSE(p.hidden(rect(10, 10, 20, 20), 0.0));
  EXPECT_TRUE(p.hidden(Poly{{8, 8}}, 7.0));           // a disc
  EXPECT_FALSE(p.hidden(Poly{{8, 8}}, 8.6));
  EXPECT_TRUE(p.hidden(Poly{}, 3.0));
  EXPECT_EQ(p.stats().hidden_calls, 7u);
  EXPECT_EQ(p.stats().hidden_true, 4u);
}

TEST(Hidden, DilationHasRoundedCorners) {
  // Everything in [0, 32)^2 covered but pixel (16, 16), whose centre (16.5, 16.5) is 6.36 px
  // from the corner (12, 12) of the square tested, and inside its mitred 6.3 px offset.
  Pyramid p(32, 32);
  p.cover(rect(0, 0, 16, 32), 0.0);
  p.cover(rect(16, 0, 32, 16), 0.0);
  p.cover(rect(17, 16, 32, 32), 0.0);
  p.cover(rect(16, 17, 17, 32), 0.0);
  ASSERT_EQ(p.covered_count(), 32u * 32u - 1u);
  ASSERT_FALSE(p.covered(16, 16));
  EXPECT_TRUE(p.hidden(rect(4, 4, 12, 12), 6.3));
  EXPECT_FALSE(p.hidden(rect(4, 4, 12, 12), 6.4));
  EXPECT_TRUE(p.hidden(Poly{{12, 12}}, 6.3));
  EXPECT_FALSE(p.hidden(Poly{{12, 12}}, 6.4));
  EXPECT_TRUE(p.hidden(Poly{{4, 12}, {12, 12}}, 6.3));  // a capsule's rounded end
  EXPECT_FALSE(p.hidden(Poly{{4, 12}, {12, 12}}, 6.4));
}

TEST(Hidden, OnlyPixelsInsideTheViewportCount) {
  Pyramid p(40, 30);
  p.cover(rect(-1, -1, 41, 31), 0.0);
  ASSERT_TRUE(p.full());
  EXPECT_TRUE(p.hidden(rect(-100, -100, 500, 500), 2.0));
  EXPECT_TRUE(p.hidden(rect(30, 20, 60, 60), 0.0));
  EXPECT_TRUE(p.hidden(rect(100, 100, 200, 200), 0.0));  // entirely outside
  p.clear();
  p.cover(rect(0, 0, 20, 30), 0.0);
  EXPECT_TRUE(p.hidden(rect(-50, -50, 19.4, 80), 0.0));
  EXPECT_FALSE(p.hidden(rect(-50, -50, 20.6, 80), 0.0));
}

TEST(Hidden, HugeOrNonFinitePointsAreVisible) {
  Pyramid p(40, 30);
  p.cover(rect(-1, -1, 41, 31), 0.0);
  EXPECT_FALSE(p.hidden(Poly{{0, 0}, {1e9, 0}, {0, 10}}, 0.0));
  EXPECT_FALSE(p.hidden(Poly{{0, 0}, {std::numeric_limits<double>::quiet_NaN(), 0}, {0, 10}}, 0.0));
}

// Random coverage states (a few polygons, sometimes many) and random queries of 1 to 8 points
// with random dilations, against the brute-force distance test; the pyramid never changes.
TEST(Hidden, RandomQueriesAgreeWithBruteForce) {
  std::mt19937 rng(99);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const int sizes[][2] = {{157, 93}, {300, 200}, {17, 900}};
  int hidden_seen = 0, visible_seen = 0;
  for (const auto& wh : sizes) {
    const int w = wh[0], h = wh[1];
    for (int state = 0; state < 12; ++state) {
      Pyramid p(w, h);
      Bitmap cov(w, h);
      const int n = state % 3 == 0 ? 40 : 4;
      for (int i = 0; i < n; ++i) {
        Poly poly = random_polygon(rng, w, h);
        if (i == 0 && state % 2) poly = rect(-1, -1, w * u(rng) + 2, h + 1.0);  // a big covered block
        p.cover(poly, 0.0);
        merge(cov, claimed_ref(poly, 0.0, w, h));
      }
      const std::uint64_t before = p.covered_count();
      for (int q = 0; q < 150; ++q) {
        Poly pts;
        const int k = std::uniform_int_distribution<int>(1, 8)(rng);
        const glm::dvec2 c(u(rng) * w * 1.2 - 0.1 * w, u(rng) * h * 1.2 - 0.1 * h);
        const double s = std::pow(10.0, u(rng) * 2.5 - 0.5);
        for (int i = 0; i < k; ++i) pts.push_back(c + s * glm::dvec2(u(rng) - 0.5, u(rng) - 0.5));
        if (q % 7 == 0) pts = Poly{glm::floor(c) + 0.5, glm::floor(c) + glm::dvec2(3.5, 0.5)};  // on centres
        const double dilation = q % 4 == 0 ? 0.0 : std::pow(10.0, u(rng) * 2.0 - 1.5);
        const bool want = hidden_ref(cov, pts, dilation);
        ASSERT_EQ(p.hidden(pts, dilation), want) << w << "x" << h << " state " << state << " query " << q << " dilation " << dilation;
        (want ? hidden_seen : visible_seen)++;
      }
      ASSERT_EQ(p.covered_count(), before);
      ASSERT_EQ(p.check_invariants(), "");
    }
  }
  EXPECT_GT(hidden_seen, 200);  // both answers are well exercised
  EXPECT_GT(visible_seen, 200);
}

}  // namespace
}  // namespace terravol::coverage
