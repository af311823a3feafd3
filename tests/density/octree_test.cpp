#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "density/octree.h"
#include "density_test_util.h"
#include "io/scene_frame.h"
#include "volume/colormap.h"

namespace terravol::density {
namespace {

using test::geographic_volume;

// A camera at `offset` from the centre of the octree's boxes, looking at it, `width` x `height`.
mrbsp::Camera looking_at_centre(const BoxGrid& g, const glm::dvec3& offset, int width, int height) {
  const glm::dvec3 centre = g.origin + 0.5 * g.size * glm::dvec3(g.boxes[0], g.boxes[1], g.boxes[2]);
  mrbsp::Camera c;
  c.eye = centre + offset;
  c.forward = glm::normalize(centre - c.eye);
  c.up = glm::normalize(glm::cross(glm::cross(c.forward, glm::dvec3(0, 0, 1)), c.forward));
  c.width = width;
  c.height = height;
  return c;
}

// A drawn box's largest side in pixels from `c` at its nearest point, or 0 for a leaf.
double size_above_leaves_px(const mrbsp::ColorBox& b, const BoxGrid& g, const mrbsp::Camera& c) {
  const glm::dvec3 lo(b.lo), hi(b.hi);
  const bool leaf = hi.x - lo.x <= g.size.x * 1.001 && hi.y - lo.y <= g.size.y * 1.001 && hi.z - lo.z <= g.size.z * 1.001;
  if (leaf) return 0.0;
  const double focal = c.height * 0.5 / std::tan(glm::radians(c.fov_y_deg) * 0.5);
  return std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z}) * focal / glm::length(glm::clamp(c.eye, lo, hi) - c.eye);
}

// A medium of one value everywhere (heights above a ground that cancels the curvature drop, so
// that every column's layers lie at the same scene heights): every cell's face has the opacity
// of its extent along the face's normal, at every level, cut to the volume or not.
TEST(Octree, HomogeneousMediumGivesEachFaceTheOpacityOfItsExtent) {
  const io::SceneFrame frame(45.0, 6.0);
  const volume::Volume v = geographic_volume(7, 6, 5, 6.0, 45.0, 0.002, 0.002, 0.0, 60.0, true, [](int, int, int) { return 120.0f; });
  const auto ground = [&](double lat, double lon) {
    return frame.curvature_drop(frame.x_of_lon(lon), frame.y_of_lat(lat));
  };
  const DensitySpec spec = parse_density("range=100:140,colormap=viridis,opacity=3");
  const ColorCubeOctree o(v, frame, ground, spec);
  EXPECT_EQ(o.grid().boxes, (std::array<int, 3>{6, 5, 4}));
  const glm::vec3 colour = glm::vec3(volume::colormap_by_name("viridis").map(0.5)) / 255.0f;
  const double sigma = 0.003;
  for (int level = 0; level < o.levels(); ++level) {
    const auto d = o.cells_at(level);
    for (int k = 0; k < d[2]; ++k)
      for (int j = 0; j < d[1]; ++j)
        for (int i = 0; i < d[0]; ++i) {
          glm::dvec3 lo, hi;
          o.cell_box(level, i, j, k, lo, hi);
          const auto faces = o.cell_faces(level, i, j, k);
          for (int f = 0; f < 6; ++f) {
            const double expected = 1.0 - std::exp(-sigma * (hi[f / 2] - lo[f / 2]));
            const glm::vec4& face = faces[static_cast<std::size_t>(f)];
            // Leaves are exact in float; cells above keep sqrt(alpha) in 8 bits.
            const double tol = level == 0 ? 1e-5 : 2.0 * std::sqrt(expected) / 255.0;
            EXPECT_NEAR(face.a, expected, tol) << "level " << level << " cell " << i << " " << j << " " << k << " face " << f;
            EXPECT_NEAR(face.g / face.a, colour.g, level == 0 ? 1e-5 : 1.0 / 255.0);
          }
        }
  }
}

// Heights above a wavy ground: each box corner takes the lattice's value at its height in its
// column (a field linear in the layer index is resampled exactly), clear outside the layers.
TEST(Octree, HeightsAboveTheGroundAreResampledAlongTheLatticeColumns) {
  const io::SceneFrame frame(45.0, 6.0);
  const volume::Volume v = geographic_volume(9, 7, 6, 6.0, 45.0, 0.003, 0.002, 10.0, 50.0, true,
                                             [](int, int, int k) { return static_cast<float>(k); });
  const auto ground = [](double lat, double lon) { return 400.0 + 3000.0 * std::sin(lat * 40.0) * std::cos(lon * 30.0); };
  const ColorCubeOctree o(v, frame, ground, parse_density("range=0:5,colormap=grey,opacity=1"));
  const BoxGrid& g = o.grid();
  int inside = 0, outside = 0;
  for (int k = 0; k <= g.boxes[2]; ++k)
    for (int j = 0; j <= g.boxes[1]; ++j)
      for (int i = 0; i <= g.boxes[0]; ++i) {
        const double x = g.origin.x + i * g.size.x, y = g.origin.y + j * g.size.y, z = g.origin.z + k * g.size.z;
        const double lat = frame.lat_of_y(y), lon = frame.lon_of_x(x);
        const double layer = (z + frame.curvature_drop(x, y) - ground(lat, lon) - 10.0) / 50.0;
        const float got = o.corner_value(i, j, k);
        if (layer >= -1e-6 && layer <= 5.0 + 1e-6) {
          ++inside;
          EXPECT_NEAR(got, layer, 1e-4) << i << " " << j << " " << k;
        } else {
          ++outside;
          EXPECT_TRUE(std::isnan(got)) << i << " " << j << " " << k << " layer " << layer;
        }
      }
  EXPECT_GT(inside, 100);
  EXPECT_GT(outside, inside) << "the ground's relief spreads the layers over many box heights";
}

// A leaf's face composites its four edges along the normal front over back, each edge as two
// halves, from the near corner's side.
TEST(Octree, LeafFacesCompositeTheirEdgesFrontOverBack) {
  const io::SceneFrame frame(45.0, 6.0);
  // Two layers: a dense blue-end value below, a clear-ish yellow-end value above.
  const volume::Volume v = geographic_volume(2, 2, 2, 6.0, 45.0, 0.001, 0.001, 0.0, 100.0, true,
                                             [](int, int, int k) { return k == 0 ? 0.0f : 1.0f; });
  const auto ground = [&](double lat, double lon) { return frame.curvature_drop(frame.x_of_lon(lon), frame.y_of_lat(lat)); };
  const ColorCubeOctree o(v, frame, ground, parse_density("range=0:1,colormap=viridis,opacity=10,ramp=down"));
  ASSERT_EQ(o.grid().boxes, (std::array<int, 3>{1, 1, 1}));
  const auto f = o.cell_faces(0, 0, 0, 0);
  const glm::vec3 c0 = glm::vec3(volume::colormap_by_name("viridis").map(0.0)) / 255.0f;
  // Seen from below (face 4) the dense bottom half is in front: 1 - exp(-0.01 * 50), then a clear
  // top half; seen from above (face 5) the same opacity, behind a clear half.
  const double a = 1.0 - std::exp(-0.01 * 50.0);
  EXPECT_NEAR(f[4].a, a, 1e-5);
  EXPECT_NEAR(f[5].a, a, 1e-5);
  EXPECT_NEAR(f[4].b / f[4].a, c0.b, 1e-5);
  // Sideways (x): each edge is all bottom (two dense halves) or all top (clear): averaged.
  EXPECT_NEAR(f[0].a, 0.5 * (1.0 - std::exp(-0.01 * o.grid().size.x)), 1e-5);
}

TEST(Octree, CoverageCompositingIsNeverLessOpaqueThanOver) {
  const io::SceneFrame frame(45.0, 6.0);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> value(60.0f, 180.0f);
  const volume::Volume v = geographic_volume(13, 11, 9, 6.0, 45.0, 0.002, 0.002, 0.0, 80.0, false, [&](int, int, int) { return value(rng); });
  const DensitySpec spec = parse_density("range=80:160,colormap=turbo,opacity=4");
  const ColorCubeOctree over(v, frame, {}, spec), cover(v, frame, {}, spec, BuildOptions{Compositing::kCoverage});
  int denser = 0;
  for (int level = 1; level < over.levels(); ++level) {
    const auto d = over.cells_at(level);
    for (int k = 0; k < d[2]; ++k)
      for (int j = 0; j < d[1]; ++j)
        for (int i = 0; i < d[0]; ++i) {
          const auto a = over.cell_faces(level, i, j, k), b = cover.cell_faces(level, i, j, k);
          for (std::size_t f = 0; f < 6; ++f) {
            EXPECT_GE(b[f].a + 2.0f / 255.0f, a[f].a);
            denser += b[f].a > a[f].a + 0.02f ? 1 : 0;
          }
        }
  }
  EXPECT_GT(denser, 0);
}

TEST(Octree, RejectsVolumesItCannotPlace) {
  const io::SceneFrame frame(45.0, 6.0);
  volume::Volume enu = geographic_volume(3, 3, 3, 6.0, 45.0, 0.001, 0.001, 0.0, 10.0, false, [](int, int, int) { return 1.0f; });
  enu.frame.kind = volume::FrameKind::kEnu;
  const DensitySpec spec = parse_density("range=0:2,colormap=grey,opacity=1");
  EXPECT_THROW(ColorCubeOctree(enu, frame, {}, spec), std::invalid_argument);
  const volume::Volume flat = geographic_volume(3, 3, 1, 6.0, 45.0, 0.001, 0.001, 0.0, 10.0, false, [](int, int, int) { return 1.0f; });
  EXPECT_THROW(ColorCubeOctree(flat, frame, {}, spec), std::invalid_argument);
  const volume::Volume agl = geographic_volume(3, 3, 3, 6.0, 45.0, 0.001, 0.001, 0.0, 10.0, true, [](int, int, int) { return 1.0f; });
  EXPECT_THROW(ColorCubeOctree(agl, frame, {}, spec), std::invalid_argument);
}

// Seeded eyes around and inside the volume: along every ray, the boxes it passes through come
// farthest first (the order mrbsp needs), and no two boxes overlap.
TEST(Octree, RefinedBoxesComeFarthestFirstAlongEveryRay) {
  const io::SceneFrame frame(45.0, 6.0);
  const volume::Volume v = test::path_loss_volume(21, 17, 9, false);
  const ColorCubeOctree o(v, frame, {}, parse_density("range=80:150,colormap=viridis,opacity=1"));
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const BoxGrid& g = o.grid();
  const glm::dvec3 centre = g.origin + 0.5 * g.size * glm::dvec3(g.boxes[0], g.boxes[1], g.boxes[2]);
  const double radius = 0.5 * glm::length(g.size * glm::dvec3(g.boxes[0], g.boxes[1], g.boxes[2]));
  std::vector<mrbsp::ColorBox> boxes;
  for (int trial = 0; trial < 24; ++trial) {
    const glm::dvec3 eye = centre + radius * (0.3 + 0.2 * (trial % 8)) * glm::normalize(glm::dvec3(u(rng), u(rng), 0.5 * u(rng)));
    mrbsp::Camera c;
    c.eye = eye;
    c.forward = glm::normalize(centre - eye + glm::dvec3(0.2 * radius * u(rng), 0.2 * radius * u(rng), 0.0));
    c.up = glm::normalize(glm::cross(glm::cross(c.forward, glm::dvec3(0, 0, 1)), c.forward));
    c.width = 200;
    c.height = 120;
    RefineOptions opt;
    opt.threshold_px = 0.5 * (1 << (trial % 5));
    opt.cull = trial % 2 == 0;
    RefineStats stats;
    boxes.clear();
    o.refine(c, opt, boxes, stats);
    ASSERT_GT(boxes.size(), 10u);
    EXPECT_EQ(stats.boxes, boxes.size());
    for (int r = 0; r < 300; ++r) {
      const glm::dvec3 d = glm::normalize(glm::dvec3(u(rng), u(rng), u(rng)));
      double last = std::numeric_limits<double>::max();
      for (const mrbsp::ColorBox& b : boxes) {
        double t0 = 0.0, t1 = std::numeric_limits<double>::max();
        for (int a = 0; a < 3; ++a) {
          if (std::abs(d[a]) < 1e-12) {
            if (eye[a] < b.lo[a] || eye[a] > b.hi[a]) t1 = -1.0;
            continue;
          }
          double ta = (b.lo[a] - eye[a]) / d[a], tb = (b.hi[a] - eye[a]) / d[a];
          if (ta > tb) std::swap(ta, tb);
          t0 = std::max(t0, ta);
          t1 = std::min(t1, tb);
        }
        if (!(t0 < t1 - 1e-6)) continue;
        EXPECT_LE(t0, last + 1e-6) << "trial " << trial;
        last = t0;
      }
    }
    if (trial < 4) {  // no overlaps (quadratic: a few views)
      for (std::size_t a = 0; a < boxes.size(); ++a)
        for (std::size_t b = a + 1; b < boxes.size(); ++b) {
          bool overlap = true;
          for (int ax = 0; ax < 3; ++ax) overlap &= boxes[a].lo[ax] < boxes[b].hi[ax] - 1e-3f && boxes[b].lo[ax] < boxes[a].hi[ax] - 1e-3f;
          ASSERT_FALSE(overlap) << a << " " << b;
        }
    }
  }
}

// Every cell drawn above the leaves spans fewer than epsilon pixels; a smaller epsilon opens
// more cells; with leaves_only and no culling, every leaf with a face not clear is drawn.
TEST(Octree, RefinementDrawsCellsBelowEpsilonAndEveryLeafWhenAsked) {
  const io::SceneFrame frame(45.0, 6.0);
  const volume::Volume v = test::path_loss_volume(33, 25, 11, false);
  const ColorCubeOctree o(v, frame, {}, parse_density("range=80:150,colormap=viridis,opacity=1"));
  const BoxGrid& g = o.grid();
  const mrbsp::Camera c = looking_at_centre(g, {-36000.0, -48000.0, 24000.0}, 640, 360);
  std::size_t last = 0;
  for (double eps : {64.0, 16.0, 4.0, 1.0}) {
    std::vector<mrbsp::ColorBox> boxes;
    RefineStats stats;
    o.refine(c, RefineOptions{eps, false, true}, boxes, stats);
    EXPECT_GT(boxes.size(), last) << "epsilon " << eps;
    last = boxes.size();
    for (const mrbsp::ColorBox& b : boxes) EXPECT_LT(size_above_leaves_px(b, g, c), eps);
  }
  std::vector<mrbsp::ColorBox> all;
  RefineStats stats;
  o.refine(c, RefineOptions{1.0, true, false}, all, stats);
  std::size_t filled = 0;
  for (int k = 0; k < g.boxes[2]; ++k)
    for (int j = 0; j < g.boxes[1]; ++j)
      for (int i = 0; i < g.boxes[0]; ++i) {
        const auto f = o.cell_faces(0, i, j, k);
        bool any = false;
        for (const auto& q : f) any |= q.a > 0.0f;
        filled += any ? 1 : 0;
      }
  EXPECT_EQ(all.size(), filled);
  EXPECT_EQ(stats.per_level[0], filled);
}

// A cell's error: 0 where its children are alike, above 0 where a step in the field runs
// through it, and never less than a child's (it stands for its whole subtree). With a
// tolerance, refinement draws fewer cells, none wider than max_size_px, and every cell it
// draws whole above epsilon is within the tolerance.
TEST(Octree, ACellsErrorMeasuresHowUnlikeItsChildrenAreAndBoundsItsSubtree) {
  const io::SceneFrame frame(45.0, 6.0);
  // 16 x 16 x 8 leaves; the value steps from 120 to 90 dB between lattice columns 8 and 9.
  const volume::Volume v =
      geographic_volume(17, 17, 9, 6.0, 45.0, 0.002, 0.002, 0.0, 60.0, false, [](int i, int, int) { return i <= 8 ? 120.0f : 90.0f; });
  const ColorCubeOctree o(v, frame, {}, parse_density("range=80:150,colormap=viridis,opacity=3"));
  ASSERT_GE(o.levels(), 3);
  // Cells above the lowest (where the frame's curvature leaves some box corners below the
  // lattice's first layer, clear).
  for (int k = 1; k < 3; ++k)
    for (int j = 0; j < 8; ++j) {
      for (int i = 0; i < 4; ++i) EXPECT_EQ(o.cell_error(1, i, j, k), 0.0) << "uniform cell " << i << " " << j << " " << k;
      EXPECT_GT(o.cell_error(1, 4, j, k), 0.0) << "the step runs through leaf 8, in cell 4";
    }
  for (int level = 2; level < o.levels(); ++level) {
    const auto d = o.cells_at(level), dc = o.cells_at(level - 1);
    for (int k = 0; k < d[2]; ++k)
      for (int j = 0; j < d[1]; ++j)
        for (int i = 0; i < d[0]; ++i)
          for (int c = 0; c < 8; ++c) {
            const int ci = 2 * i + (c & 1), cj = 2 * j + ((c >> 1) & 1), ck = 2 * k + (c >> 2);
            if (ci >= dc[0] || cj >= dc[1] || ck >= dc[2]) continue;
            EXPECT_GE(o.cell_error(level, i, j, k), o.cell_error(level - 1, ci, cj, ck));
          }
  }
  // Refinement: a seeded path-loss field from a near camera.
  const volume::Volume field = test::path_loss_volume(33, 25, 11, false);
  const ColorCubeOctree p(field, frame, {}, parse_density("range=80:150,colormap=viridis,opacity=1"));
  const mrbsp::Camera c = looking_at_centre(p.grid(), {-3600.0, -4800.0, 2400.0}, 640, 360);
  std::size_t last = std::numeric_limits<std::size_t>::max();
  for (const double tolerance : {0.0, 2.0 / 255.0, 8.0 / 255.0, 32.0 / 255.0}) {
    RefineOptions options;
    options.error_tolerance = tolerance;
    std::vector<mrbsp::ColorBox> boxes;
    RefineStats stats;
    p.refine(c, options, boxes, stats);
    EXPECT_LE(boxes.size(), last) << "tolerance " << tolerance * 255.0;
    last = boxes.size();
    for (const mrbsp::ColorBox& b : boxes) {
      EXPECT_LT(size_above_leaves_px(b, p.grid(), c), tolerance > 0.0 ? options.max_size_px : options.threshold_px);
    }
  }
  EXPECT_LT(last, 100000u);
}

// Chamberlain's O(log n): far away, a lattice refined twice per axis draws about as many cells
// (the extra level is never opened).
TEST(Octree, AFarViewDrawsAboutAsManyCellsWhenTheLatticeIsRefined) {
  const io::SceneFrame frame(45.0, 6.0);
  const volume::Volume coarse = test::path_loss_volume(17, 17, 9, false);
  const volume::Volume fine = test::refined(coarse, 2);
  const DensitySpec spec = parse_density("range=80:150,colormap=viridis,opacity=1");
  const ColorCubeOctree a(coarse, frame, {}, spec), b(fine, frame, {}, spec);
  EXPECT_EQ(b.levels(), a.levels() + 1);
  // Leaves of the coarse lattice well below a pixel.
  const mrbsp::Camera c = looking_at_centre(a.grid(), {-300000.0, -400000.0, 200000.0}, 1280, 720);
  std::vector<mrbsp::ColorBox> ba, bb;
  RefineStats sa, sb;
  a.refine(c, RefineOptions{1.0, false, true}, ba, sa);
  b.refine(c, RefineOptions{1.0, false, true}, bb, sb);
  EXPECT_EQ(sb.per_level[0], 0u) << "no leaf of the fine lattice is opened";
  EXPECT_LT(static_cast<double>(bb.size()), 1.3 * static_cast<double>(ba.size()));
  EXPECT_GT(static_cast<double>(bb.size()), 0.7 * static_cast<double>(ba.size()));
}

}  // namespace
}  // namespace terravol::density
