// Textured slices against the exact sheet of slice(), checked by brute force: vertices are
// slice()'s, every slice() vertex lies within the tolerance of the simplified sheet, the
// boundary is slice()'s outer boundary (no crack), texels are the colour map of the trilinear
// value recomputed here, texture coordinates are texel centres; tiny exact cases; the cap.
#include "volume/textured_slice.h"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>
#include <set>
#include <stdexcept>
#include <tuple>

#include "volume/colormap.h"
#include "mesh_test_util.h"

namespace terravol::volume {
namespace {

using namespace test;

using UV = std::pair<int, int>;

// Rough ground: the smooth hills plus seeded sharp bumps (tens of metres over a few cells), so
// the sheet of an agl slice needs every level of the quadtree.
GroundFunction bumpy_ground(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  struct Bump {
    double lat, lon, h, r;
  };
  std::vector<Bump> bumps;
  for (int b = 0; b < 12; ++b) {
    bumps.push_back({kLat0 - 0.01 + 0.025 * u(rng), kLon0 - 0.01 + 0.035 * u(rng), 80.0 * (u(rng) - 0.3), 0.0005 + 0.002 * u(rng)});
  }
  return [bumps](double lat, double lon) {
    double h = hills(lat, lon);
    for (const Bump& b : bumps) {
      const double d2 = ((lat - b.lat) * (lat - b.lat) + (lon - b.lon) * (lon - b.lon)) / (b.r * b.r);
      h += b.h * std::exp(-d2);
    }
    return h;
  };
}

// The lattice (u, v) of a sheet vertex: the two lattice coordinates other than the line's axis.
UV sheet_uv(const Scene& s, SliceKind kind, const glm::dvec3& p) {
  const glm::dvec3 q = lattice_of(s.volume, s.frame, p);
  switch (kind) {
    case SliceKind::kLat:
      return {static_cast<int>(std::lround(q.x)), static_cast<int>(std::lround(q.z))};
    case SliceKind::kLon:
      return {static_cast<int>(std::lround(q.y)), static_cast<int>(std::lround(q.z))};
    default:
      return {static_cast<int>(std::lround(q.x)), static_cast<int>(std::lround(q.y))};
  }
}

// What holds in any frame: valid, slice()'s vertices with their colours, every slice() vertex
// within `tolerance` of the simplified sheet, consistently oriented, and the same outline (the
// boundary's length is the exact one's: straight runs of it merge into longer edges, which
// shortens it only where those runs are not straight, by far less than 1% here).
void expect_subset_within(const Mesh& exact, const TexturedMesh& t, double tolerance, const std::string& what) {
  const Mesh& m = t.mesh;
  expect_valid(m);
  ASSERT_FALSE(m.empty()) << what;
  ASSERT_EQ(t.tcoords.size(), m.vertices.size()) << what;
  ASSERT_EQ(t.texels.size(), static_cast<std::size_t>(t.width) * static_cast<std::size_t>(t.height)) << what;
  EXPECT_LE(m.triangle_count(), exact.triangle_count()) << what;
  std::map<std::tuple<double, double, double>, glm::u8vec4> exact_vertices;
  for (std::size_t k = 0; k < exact.vertices.size(); ++k) {
    exact_vertices[{exact.vertices[k].x, exact.vertices[k].y, exact.vertices[k].z}] = exact.colors[k];
  }
  for (std::size_t k = 0; k < m.vertices.size(); ++k) {
    const auto it = exact_vertices.find({m.vertices[k].x, m.vertices[k].y, m.vertices[k].z});
    ASSERT_NE(it, exact_vertices.end()) << what << ": vertex " << k << " is not one of slice()'s";
    EXPECT_EQ(m.colors[k], it->second) << what;
  }
  double worst = 0.0;
  for (const glm::dvec3& p : exact.vertices) worst = std::max(worst, distance_to_mesh(p, m));
  EXPECT_LE(worst, tolerance + 1e-6) << what;
  auto boundary_length = [&](const Mesh& mesh) {
    const auto edges = directed_edges(mesh);
    double length = 0.0;
    for (const auto& [e, count] : edges) {
      EXPECT_EQ(count, 1) << what << ": a directed edge used twice (orientation or overlap)";
      if (!edges.contains({e.second, e.first})) length += glm::length(mesh.vertices[e.first] - mesh.vertices[e.second]);
    }
    return length;
  };
  const double exact_boundary = boundary_length(exact);
  EXPECT_NEAR(boundary_length(m), exact_boundary, 0.01 * exact_boundary) << what;
}

// Checks a textured slice against slice() for the same spec: vertices, tolerance, boundary,
// footprint, orientation, texture coordinates and texels at vertices.
void expect_simplifies(const Scene& s, const SliceSpec& spec, const TexturedMesh& t, double tolerance,
                       const std::string& what) {
  const Mesh exact = slice(s.volume, s.mapper, spec, s.ground);
  expect_subset_within(exact, t, tolerance, what);
  const Mesh& m = t.mesh;
  // Texture coordinates at their texel's centre, which has the vertex's colour.
  for (std::size_t k = 0; k < m.vertices.size(); ++k) {
    const auto [u, v] = sheet_uv(s, spec.kind, m.vertices[k]);
    EXPECT_NEAR(t.tcoords[k].x, (u + 0.5) / t.width, 1e-6) << what;
    EXPECT_NEAR(t.tcoords[k].y, (v + 0.5) / t.height, 1e-6) << what;
    EXPECT_EQ(t.texels[static_cast<std::size_t>(v) * t.width + u], m.colors[k]) << what;
  }

  // Cells slice() draws, and its boundary as unit steps in (u, v).
  std::set<UV> cells;
  for (std::size_t tr = 0; tr < exact.triangle_count(); ++tr) {
    UV lo{1 << 30, 1 << 30};
    for (int c = 0; c < 3; ++c) {
      const UV uv = sheet_uv(s, spec.kind, exact.vertices[exact.triangles[3 * tr + c]]);
      lo = {std::min(lo.first, uv.first), std::min(lo.second, uv.second)};
    }
    cells.insert(lo);
  }
  auto boundary_steps = [&](const Mesh& mesh, bool split) {
    std::multiset<std::pair<UV, UV>> steps;
    const auto edges = directed_edges(mesh);
    for (const auto& [e, count] : edges) {
      if (edges.contains({e.second, e.first})) continue;
      const UV a = sheet_uv(s, spec.kind, mesh.vertices[e.first]), b = sheet_uv(s, spec.kind, mesh.vertices[e.second]);
      EXPECT_TRUE(a.first == b.first || a.second == b.second) << what << ": a boundary edge across the grid";
      if (!split) {
        steps.insert({a, b});
        continue;
      }
      const int n = std::abs(b.first - a.first) + std::abs(b.second - a.second);
      const UV d{(b.first - a.first) / std::max(1, n), (b.second - a.second) / std::max(1, n)};
      for (int i = 0; i < n; ++i) {
        steps.insert({{a.first + i * d.first, a.second + i * d.second}, {a.first + (i + 1) * d.first, a.second + (i + 1) * d.second}});
      }
    }
    return steps;
  };
  EXPECT_EQ(boundary_steps(m, true), boundary_steps(exact, false)) << what << ": the boundaries differ (a crack?)";

  // Footprint: every simplified triangle lies over cells slice() draws; normals agree.
  const glm::dvec3 n0 = glm::cross(exact.vertices[exact.triangles[1]] - exact.vertices[exact.triangles[0]],
                                   exact.vertices[exact.triangles[2]] - exact.vertices[exact.triangles[0]]);
  for (std::size_t tr = 0; tr < m.triangle_count(); ++tr) {
    double cu = 0, cv = 0;
    for (int c = 0; c < 3; ++c) {
      const UV uv = sheet_uv(s, spec.kind, m.vertices[m.triangles[3 * tr + c]]);
      cu += uv.first / 3.0;
      cv += uv.second / 3.0;
    }
    EXPECT_TRUE(cells.contains({static_cast<int>(std::floor(cu)), static_cast<int>(std::floor(cv))})) << what;
    const glm::dvec3 n = glm::cross(m.vertices[m.triangles[3 * tr + 1]] - m.vertices[m.triangles[3 * tr]],
                                    m.vertices[m.triangles[3 * tr + 2]] - m.vertices[m.triangles[3 * tr]]);
    EXPECT_GT(glm::dot(n, n0), 0.0) << what << ": triangle " << tr << " is flipped";
  }
}

TEST(TexturedSlice, AglSheetsOverRoughGroundStayWithinTheTolerance) {
  for (unsigned seed : {1u, 2u, 3u}) {
    const GroundFunction ground = bumpy_ground(seed);
    Scene s(geographic_volume({33, 29, 40}), ground);  // heights 100 .. 2050 m
    const SliceSpec spec = at(SliceKind::kAgl, 300.0);
    std::size_t previous = SIZE_MAX;
    for (double tolerance : {0.0, 0.5, 2.0, 10.0, 50.0}) {
      SheetOptions o;
      o.tolerance_m = tolerance;
      const TexturedMesh t = textured_slice(s.volume, s.mapper, spec, ground, o);
      const std::string what = "seed " + std::to_string(seed) + " tolerance " + std::to_string(tolerance);
      expect_simplifies(s, spec, t, tolerance, what);
      EXPECT_EQ(t.tolerance_m, tolerance);
      EXPECT_LE(t.mesh.triangle_count(), previous) << what;
      previous = t.mesh.triangle_count();
    }
    EXPECT_LT(previous, 2u * 32u * 28u / 4u) << "seed " << seed << ": 50 m merges most of the sheet";
  }
}

// Spikes one sample wide on flat ground, at seeded columns (so at every position within the
// quadtree's nodes: corners, edge midpoints, quarter points, centres): each must keep the
// sheet's triangles fine enough around it.
TEST(TexturedSlice, OneSampleSpikesAreKept) {
  Volume v = geographic_volume({34, 34, 30});
  const auto& l = v.lattice;
  std::mt19937 rng(123);
  std::uniform_int_distribution<int> column(0, 33);
  std::vector<std::pair<double, double>> spikes;
  for (int n = 0; n < 25; ++n) spikes.push_back({l.world(1, column(rng)), l.world(0, column(rng))});
  const GroundFunction ground = [spikes, &l](double lat, double lon) {
    double h = 500.0;
    for (const auto& [slat, slon] : spikes) {
      const double d2 = std::pow((lat - slat) / l.spacing[1], 2) + std::pow((lon - slon) / l.spacing[0], 2);
      h += 40.0 * std::exp(-d2 / 0.02);  // 40 m at the column, nothing one column away
    }
    return h;
  };
  Scene s(std::move(v), ground);
  for (double tolerance : {1.0, 10.0, 30.0}) {
    SheetOptions o;
    o.tolerance_m = tolerance;
    const SliceSpec spec = at(SliceKind::kAgl, 200.0);
    const TexturedMesh t = textured_slice(s.volume, s.mapper, spec, ground, o);
    expect_simplifies(s, spec, t, tolerance, "tolerance " + std::to_string(tolerance));
    EXPECT_LT(t.mesh.triangle_count(), 2u * 33u * 33u * 3u / 4u) << "flat parts merge";
  }
}

TEST(TexturedSlice, EveryKindMatchesTheExactSheet) {
  std::mt19937 rng(5150);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int trial = 0; trial < 3; ++trial) {
    Scene geo(geographic_volume({26, 21, 12}), bumpy_ground(10 + trial));
    const auto& l = geo.volume.lattice;
    const SliceSpec specs[] = {at(SliceKind::kLat, l.origin[1] + (2.0 + 16.0 * u(rng)) * l.spacing[1]),
                               at(SliceKind::kLon, l.origin[0] + (2.0 + 20.0 * u(rng)) * l.spacing[0]),
                               at(SliceKind::kAlt, 120.0 + 500.0 * u(rng)), at(SliceKind::kAgl, 100.0 + 50.0 * u(rng))};
    for (const SliceSpec& spec : specs) {
      SheetOptions o;
      o.tolerance_m = 0.2 + 5.0 * u(rng);
      const TexturedMesh t = textured_slice(geo.volume, geo.mapper, spec, geo.ground, o);
      expect_simplifies(geo, spec, t, o.tolerance_m,
                        "trial " + std::to_string(trial) + " " + std::string(slice_kind_name(spec.kind)));
    }
  }
}

// ENU volumes: crossings found by iteration; the sheets are slice()'s, simplified.
TEST(TexturedSlice, EnuSheetsAreSimplifiedExactSheets) {
  std::mt19937 rng(31);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const io::SceneFrame frame(kLat0, kLon0);
  for (int trial = 0; trial < 3; ++trial) {
    const double cell = 100.0 + 200.0 * u(rng);
    Volume v = make_volume({21, 19, 12}, FrameKind::kEnu, HeightRef::kDatum, {-10.0 * cell, -9.0 * cell, -200.0},
                           {cell, cell, 100.0});
    const LatticeMapper mapper(v, frame);
    const io::Geodetic sw = mapper.geodetic(0, 0, 0), ne = mapper.geodetic(20, 18, 0);
    for (const SliceSpec& spec : {at(SliceKind::kLat, sw.lat + (ne.lat - sw.lat) * (0.1 + 0.8 * u(rng))),
                                  at(SliceKind::kLon, sw.lon + (ne.lon - sw.lon) * (0.1 + 0.8 * u(rng))),
                                  at(SliceKind::kAlt, 400.0 + 800.0 * u(rng))}) {
      SheetOptions o;
      o.tolerance_m = 0.05 + 2.0 * u(rng);
      const TexturedMesh t = textured_slice(v, mapper, spec, {}, o);
      expect_subset_within(slice(v, mapper, spec, {}), t, o.tolerance_m,
                           "trial " + std::to_string(trial) + " " + std::string(slice_kind_name(spec.kind)));
    }
  }
}

// NaN points and lines that miss the slice: holes, whose edges are slice()'s edges.
TEST(TexturedSlice, HolesKeepTheExactBoundary) {
  std::mt19937 rng(77);
  std::uniform_int_distribution<int> i(0, 24), j(0, 20), k(0, 11);
  for (int trial = 0; trial < 4; ++trial) {
    Volume v = geographic_volume({25, 21, 12}, HeightRef::kGround);  // 100 .. 650 m above ground
    for (float& x : v.values) x = 1.0f;
    for (int n = 0; n < 15; ++n) v.values[v.lattice.index(i(rng), j(rng), k(rng))] = std::nanf("");
    Scene s(std::move(v), hills);
    // 1000 m above the datum misses the columns where the ground is under 350 m or over 900 m.
    for (const SliceSpec& spec : {at(SliceKind::kAlt, 1000.0), at(SliceKind::kAgl, 333.0)}) {
      SheetOptions o;
      o.tolerance_m = 5.0;
      const TexturedMesh t = textured_slice(s.volume, s.mapper, spec, hills, o);
      // The terrain-following lattice is not lattice_of's frame: what holds in any frame.
      expect_subset_within(slice(s.volume, s.mapper, spec, hills), t, o.tolerance_m,
                           "trial " + std::to_string(trial) + " " + std::string(slice_kind_name(spec.kind)));
    }
  }
}

// Texels recomputed here: the crossing of an alt slice in a geographic datum volume is at
// lattice height (alt - z0) / dz on every column, the value linear between the two points
// about it, NaN where a point with a weight > 0 is NaN; the colour is the map at
// (value - lo) / (hi - lo) with alpha round(opacity * 255). Lines that miss: alpha 0.
TEST(TexturedSlice, TexelsAreTheColourMapOfTheTrilinearValue) {
  std::mt19937 rng(99);
  std::uniform_real_distribution<float> value(-150.0f, -40.0f);
  Scene s(geographic_volume({17, 13, 9}));
  for (float& x : s.volume.values) x = value(rng);
  s.volume.values[s.volume.lattice.index(3, 4, 2)] = std::nanf("");  // below the slice: weight > 0
  s.volume.values[s.volume.lattice.index(9, 9, 5)] = std::nanf("");  // far above: weight 0
  const Colormap map = colormap_by_name("turbo");
  SliceSpec spec = at(SliceKind::kAlt, 100.0 + 2.4 * 50.0);  // between k = 2 and k = 3
  spec.colormap = "turbo";
  spec.opacity = 0.7;
  spec.lo = -140.0f;
  spec.hi = -50.0f;
  const TexturedMesh t = textured_slice(s.volume, s.mapper, spec, {});
  ASSERT_EQ(t.width, 17);
  ASSERT_EQ(t.height, 13);
  for (int b = 0; b < 13; ++b)
    for (int a = 0; a < 17; ++a) {
      const double k = 2.4, w = k - 2.0;
      const float v0 = s.volume.at(a, b, 2), v1 = s.volume.at(a, b, 3);
      const glm::u8vec4 texel = t.texels[static_cast<std::size_t>(b) * 17 + a];
      if (std::isnan(v0) || std::isnan(v1)) {
        EXPECT_EQ(texel.a, 0) << a << "," << b;
        continue;
      }
      const double x = (1.0 - w) * v0 + w * v1;
      const glm::u8vec3 want = map.map((x + 140.0) / 90.0);
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(texel[c], want[c], 1) << a << "," << b;  // float rounding of the value
      EXPECT_EQ(texel.a, 179) << a << "," << b;
    }
  EXPECT_EQ(t.texels[4 * 17 + 3].a, 0);
  EXPECT_EQ(t.texels[9 * 17 + 9].a, 179);

  // A terrain-following volume (100 .. 500 m above the hills): 1000 m above the datum is inside
  // the column only where the ground is 500 .. 900 m.
  Scene f(geographic_volume({17, 13, 9}, HeightRef::kGround), hills);
  for (float& x : f.volume.values) x = -90.0f;
  const TexturedMesh ft = textured_slice(f.volume, f.mapper, at(SliceKind::kAlt, 1000.0), hills);
  int missed = 0, crossed = 0;
  for (int b = 0; b < 13; ++b)
    for (int a = 0; a < 17; ++a) {
      const double lat = f.volume.lattice.world(1, b), lon = f.volume.lattice.world(0, a);
      const double above = 1000.0 - hills(lat, lon);
      if (std::abs(above - 100.0) < 1.0 || std::abs(above - 500.0) < 1.0) continue;
      const bool inside = above > 100.0 && above < 500.0;
      EXPECT_EQ(ft.texels[static_cast<std::size_t>(b) * 17 + a].a, inside ? 128 : 0) << a << "," << b;
      (inside ? crossed : missed) += 1;
    }
  EXPECT_GT(missed, 0);
  EXPECT_GT(crossed, 0);
}

// Alt slices of small lattices at a tolerance above any deviation: 5 x 5 and 9 x 9 lines are
// one node (a fan of 4 triangles); 4 x 4 lines hold one 2 x 2 node, whose neighbours to the
// right and above reach past the grid and are split, so its fan takes both edge midpoints (6
// triangles), plus the other 5 cells (10 triangles). At tolerance 0 nothing merges.
TEST(TexturedSlice, SmallLatticesGiveKnownCounts) {
  SheetOptions loose;
  loose.tolerance_m = 1e6;
  SheetOptions exact;
  exact.tolerance_m = 0.0;
  const std::pair<int, std::size_t> cases[] = {{5, 4}, {9, 4}, {4, 16}, {2, 2}};
  for (const auto& [n, triangles] : cases) {
    Scene s(geographic_volume({n, n, 3}));
    const TexturedMesh t = textured_slice(s.volume, s.mapper, at(SliceKind::kAlt, 160.0), {}, loose);
    expect_valid(t.mesh);
    EXPECT_EQ(t.mesh.triangle_count(), triangles) << n << " x " << n;
    const TexturedMesh e = textured_slice(s.volume, s.mapper, at(SliceKind::kAlt, 160.0), {}, exact);
    EXPECT_EQ(e.mesh.triangle_count(), 2u * (n - 1) * (n - 1)) << n << " x " << n;
  }
}

TEST(TexturedSlice, TriangleCapRaisesTheTolerance) {
  const GroundFunction ground = bumpy_ground(4);
  Scene s(geographic_volume({40, 36, 40}), ground);
  const SliceSpec spec = at(SliceKind::kAgl, 250.0);
  SheetOptions o;
  o.tolerance_m = 0.5;
  const std::size_t uncapped = textured_slice(s.volume, s.mapper, spec, ground, o).mesh.triangle_count();
  SheetOptions loosest;
  loosest.tolerance_m = 1e9;
  const std::size_t fewest = textured_slice(s.volume, s.mapper, spec, ground, loosest).mesh.triangle_count();
  ASSERT_LT(fewest, 600u);
  for (std::size_t cap : {uncapped + 10, uncapped / 2, std::size_t{600}, std::size_t{4}}) {
    o.max_triangles = cap;
    const TexturedMesh t = textured_slice(s.volume, s.mapper, spec, ground, o);
    const std::string what = "cap " + std::to_string(cap);
    EXPECT_LE(t.mesh.triangle_count(), std::max(cap, fewest)) << what;
    EXPECT_GE(t.tolerance_m, o.tolerance_m) << what;
    if (cap > uncapped) {
      EXPECT_EQ(t.mesh.triangle_count(), uncapped) << what;
      EXPECT_EQ(t.tolerance_m, o.tolerance_m) << what;
    }
    if (cap < fewest) {
      EXPECT_EQ(t.mesh.triangle_count(), fewest) << what;  // every merge there is
    }
    expect_simplifies(s, spec, t, t.tolerance_m, what);
  }
}

TEST(TexturedSlice, BadToleranceAndOutsideThrow) {
  Scene s(geographic_volume({10, 8, 6}));
  SheetOptions o;
  o.tolerance_m = -1.0;
  EXPECT_THROW(textured_slice(s.volume, s.mapper, at(SliceKind::kAlt, 200.0), {}, o), std::invalid_argument);
  o.tolerance_m = NAN;
  EXPECT_THROW(textured_slice(s.volume, s.mapper, at(SliceKind::kAlt, 200.0), {}, o), std::invalid_argument);
  EXPECT_THROW(textured_slice(s.volume, s.mapper, at(SliceKind::kAlt, 5000.0), {}), std::invalid_argument);
  EXPECT_THROW(textured_slice(s.volume, s.mapper, at(SliceKind::kAgl, 200.0), {}), std::invalid_argument);
}

}  // namespace
}  // namespace terravol::volume
