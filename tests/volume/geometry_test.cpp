// Volume geometry: isosurfaces (exact tiny cases, seeded spheres, NaN holes), slices (each kind
// on geographic, terrain-following and ENU volumes, colours, NaN, outside), the parsers, and
// both on a propagation volume over the bundled DEM.
#include "volume/geometry.h"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>
#include <vtkMath.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <numbers>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>

#include "io/dem_file.h"
#include "io/mosaic.h"
#include "volume/colormap.h"
#include "volume/propagation.h"
#include "mesh_test_util.h"

namespace terravol::volume {
namespace {

using namespace test;

// ---- Isosurfaces -------------------------------------------------------------------------

TEST(Isosurface, OneCornerAboveGivesOneTriangleAtEdgeMidpoints) {
  Volume v = geographic_volume({2, 2, 2});
  v.values[v.lattice.index(0, 0, 0)] = 2.0f;
  const io::SceneFrame frame(kLat0, kLon0);
  const LatticeMapper mapper(v, frame);
  const glm::u8vec4 rgba(10, 20, 30, 40);
  const Mesh m = isosurface(v, mapper, 1.0f, rgba);
  expect_valid(m);
  ASSERT_EQ(m.triangle_count(), 1u);
  std::vector<glm::dvec3> want;
  for (auto [i, j, k] : {std::array{0.5, 0.0, 0.0}, std::array{0.0, 0.5, 0.0}, std::array{0.0, 0.0, 0.5}}) {
    const io::ScenePoint p = mapper.scene(i, j, k);
    want.emplace_back(p.x, p.y, p.z);
  }
  for (const glm::dvec3& p : m.vertices) {
    const double d = std::min({glm::length(p - want[0]), glm::length(p - want[1]), glm::length(p - want[2])});
    EXPECT_LT(d, 1e-3);
  }
  for (const glm::u8vec4& c : m.colors) EXPECT_EQ(c, rgba);
  // The values rise towards the corner: the normal points at it.
  const glm::dvec3 a = m.vertices[m.triangles[0]], b = m.vertices[m.triangles[1]], c = m.vertices[m.triangles[2]];
  const io::ScenePoint corner = mapper.scene(0, 0, 0);
  EXPECT_GT(glm::dot(glm::cross(b - a, c - a), glm::dvec3(corner.x, corner.y, corner.z) - a), 0.0);
}

TEST(Isosurface, LevelNotCrossedOrFlatVolumeGivesNothing) {
  Volume v = geographic_volume({4, 4, 4});
  const io::SceneFrame frame(kLat0, kLon0);
  EXPECT_TRUE(isosurface(v, LatticeMapper(v, frame), 1.0f, {255, 0, 0, 255}).empty());
  Volume flat = geographic_volume({4, 4, 1});
  flat.values[0] = 5.0f;
  EXPECT_TRUE(isosurface(flat, LatticeMapper(flat, frame), 1.0f, {255, 0, 0, 255}).empty());
}

TEST(Isosurface, NonFiniteLevelThrows) {
  Volume v = geographic_volume({4, 4, 4});
  const io::SceneFrame frame(kLat0, kLon0);
  EXPECT_THROW(isosurface(v, LatticeMapper(v, frame), std::nanf(""), {255, 0, 0, 255}), std::invalid_argument);
  EXPECT_THROW(isosurface(v, LatticeMapper(v, frame), INFINITY, {255, 0, 0, 255}), std::invalid_argument);
}

// A linear field through lattice points (values equal to the level on the points of the plane
// i + j + k = 5): the surface is that plane, exact, with no degenerate or duplicate pieces.
TEST(Isosurface, LevelThroughLatticePointsGivesTheExactPlane) {
  Volume v = geographic_volume({6, 6, 6});
  for (int k = 0; k < 6; ++k)
    for (int j = 0; j < 6; ++j)
      for (int i = 0; i < 6; ++i) v.values[v.lattice.index(i, j, k)] = static_cast<float>(i + j + k);
  const io::SceneFrame frame(kLat0, kLon0);
  const LatticeMapper mapper(v, frame);
  const Mesh m = isosurface(v, mapper, 5.0f, {255, 255, 255, 255});
  expect_valid(m);
  ASSERT_FALSE(m.empty());
  for (const glm::dvec3& p : m.vertices) {
    const glm::dvec3 q = lattice_of(v, frame, p);
    EXPECT_NEAR(q.x + q.y + q.z, 5.0, 1e-4);
  }
  // Interior edges are shared by exactly two triangles, in opposite directions.
  for (const auto& [edge, count] : directed_edges(m)) {
    EXPECT_EQ(count, 1);
  }
  double area = 0.0;
  for (std::size_t t = 0; t < m.triangle_count(); ++t) area += triangle_area(m, t);
  // The triangle (5,0,0), (0,5,0), (0,0,5) in the scene frame (the map is affine to 1e-6 here).
  const io::ScenePoint a = mapper.scene(5, 0, 0), b = mapper.scene(0, 5, 0), c = mapper.scene(0, 0, 5);
  const glm::dvec3 pa(a.x, a.y, a.z), pb(b.x, b.y, b.z), pc(c.x, c.y, c.z);
  EXPECT_NEAR(area, 0.5 * glm::length(glm::cross(pb - pa, pc - pa)), 1e-4 * area);
}

// Seeded spheres inside the lattice (distance to a centre, in scene metres): every vertex is
// on the sphere within the interpolation bound h^2 / (8 (r - h)), h the longest cell edge; the
// surface is closed and consistently oriented with the normals outwards (towards increasing
// distance); its area and enclosed volume are within 2% of the sphere's.
TEST(Isosurface, SpheresAreClosedAndOnTheSphere) {
  std::mt19937 rng(4242);
  const io::SceneFrame frame(kLat0, kLon0);
  Volume v = geographic_volume({40, 40, 40});
  const LatticeMapper mapper(v, frame);
  double h = 0.0;  // the longest cell edge
  for (auto [di, dj, dk] : {std::array{1, 0, 0}, std::array{0, 1, 0}, std::array{0, 0, 1}}) {
    const io::ScenePoint a = mapper.scene(20, 20, 20), b = mapper.scene(20 + di, 20 + dj, 20 + dk);
    h = std::max(h, std::hypot(b.x - a.x, b.y - a.y, b.z - a.z));
  }
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int trial = 0; trial < 8; ++trial) {
    const double r = (6.0 + 8.0 * u(rng)) * h;  // 6 to 14 cells
    // A centre at least r + 2 cells inside, in lattice coordinates, then in the scene.
    const double margin = r / 50.0 + 2.0;  // cells are at least 50 m
    const io::ScenePoint cs = mapper.scene(margin + (39.0 - 2 * margin) * u(rng), margin + (39.0 - 2 * margin) * u(rng),
                                           margin + (39.0 - 2 * margin) * u(rng));
    const glm::dvec3 centre(cs.x, cs.y, cs.z);
    fill(v, mapper, [&](const glm::dvec3& p) { return glm::length(p - centre); });
    const Mesh m = isosurface(v, mapper, static_cast<float>(r), {0, 128, 255, 100});
    expect_valid(m);
    ASSERT_GT(m.triangle_count(), 100u) << "trial " << trial;
    const double bound = h * h / (8.0 * (r - h)) + 0.01;  // + float rounding of the field and points
    double worst = 0.0;
    for (const glm::dvec3& p : m.vertices) worst = std::max(worst, std::abs(glm::length(p - centre) - r));
    EXPECT_LE(worst, bound) << "trial " << trial << " r=" << r;
    const auto edges = directed_edges(m);
    for (const auto& [edge, count] : edges) {
      ASSERT_EQ(count, 1) << "trial " << trial;
      ASSERT_TRUE(edges.contains({edge.second, edge.first})) << "trial " << trial << ": an open edge";
    }
    // Euler characteristic of a sphere.
    const long V = static_cast<long>(m.vertices.size()), E = static_cast<long>(edges.size() / 2),
               F = static_cast<long>(m.triangle_count());
    EXPECT_EQ(V - E + F, 2) << "trial " << trial;
    double area = 0.0, volume = 0.0;
    for (std::size_t t = 0; t < m.triangle_count(); ++t) {
      area += triangle_area(m, t);
      const glm::dvec3 a = m.vertices[m.triangles[3 * t]] - centre, b = m.vertices[m.triangles[3 * t + 1]] - centre,
                       c = m.vertices[m.triangles[3 * t + 2]] - centre;
      volume += glm::dot(a, glm::cross(b, c)) / 6.0;
    }
    const double pi = std::numbers::pi;
    EXPECT_NEAR(area / (4.0 * pi * r * r), 1.0, 0.02) << "trial " << trial << " r/h=" << r / h;
    EXPECT_NEAR(volume / (4.0 / 3.0 * pi * r * r * r), 1.0, 0.02) << "trial " << trial;
  }
}

// NaN points: the mesh is the NaN-free mesh minus exactly its triangles in cells with a NaN
// corner; nothing new appears and no vertex is NaN.
TEST(Isosurface, NanPointsLeaveHolesAndNothingElse) {
  std::mt19937 rng(77);
  const io::SceneFrame frame(kLat0, kLon0);
  Volume v = geographic_volume({30, 30, 30});
  const LatticeMapper mapper(v, frame);
  const io::ScenePoint cs = mapper.scene(14.5, 15.2, 14.8);
  const glm::dvec3 centre(cs.x, cs.y, cs.z);
  fill(v, mapper, [&](const glm::dvec3& p) { return glm::length(p - centre); });
  const float level = 500.0f;
  const Mesh clean = isosurface(v, mapper, level, {255, 255, 255, 255});
  for (int trial = 0; trial < 5; ++trial) {
    Volume holed = v;
    std::set<std::array<int, 3>> nan_points;
    std::uniform_int_distribution<int> index(1, 28);
    while (nan_points.size() < 25) {
      const std::array<int, 3> p{index(rng), index(rng), index(rng)};
      const io::ScenePoint s = mapper.scene(p[0], p[1], p[2]);
      if (std::abs(glm::length(glm::dvec3(s.x, s.y, s.z) - centre) - level) > 150.0) continue;  // near the surface
      nan_points.insert(p);
      holed.values[holed.lattice.index(p[0], p[1], p[2])] = std::nanf("");
    }
    auto in_nan_cell = [&](const glm::dvec3& c) {
      const glm::dvec3 q = lattice_of(v, frame, c);
      const std::array<int, 3> cell{int(std::floor(q.x)), int(std::floor(q.y)), int(std::floor(q.z))};
      for (const auto& p : nan_points)
        if (p[0] - cell[0] >= 0 && p[0] - cell[0] <= 1 && p[1] - cell[1] >= 0 && p[1] - cell[1] <= 1 &&
            p[2] - cell[2] >= 0 && p[2] - cell[2] <= 1)
          return true;
      return false;
    };
    const Mesh m = isosurface(holed, mapper, level, {255, 255, 255, 255});
    expect_valid(m);
    std::vector<glm::dvec3> kept;
    std::size_t dropped = 0;
    for (std::size_t t = 0; t < clean.triangle_count(); ++t) {
      if (in_nan_cell(centroid(clean, t))) {
        ++dropped;
      } else {
        kept.push_back(centroid(clean, t));
      }
    }
    EXPECT_GT(dropped, 0u) << "trial " << trial;
    ASSERT_EQ(m.triangle_count(), kept.size()) << "trial " << trial;
    auto less = [](const glm::dvec3& a, const glm::dvec3& b) {
      return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z);
    };
    std::vector<glm::dvec3> got;
    for (std::size_t t = 0; t < m.triangle_count(); ++t) got.push_back(centroid(m, t));
    std::sort(kept.begin(), kept.end(), less);
    std::sort(got.begin(), got.end(), less);
    for (std::size_t t = 0; t < got.size(); ++t) EXPECT_LT(glm::length(got[t] - kept[t]), 1e-6) << "trial " << trial;
  }
}

TEST(Isosurface, TerrainFollowingVolumeLiftsVerticesByTheGround) {
  Volume v = geographic_volume({5, 5, 5}, HeightRef::kGround);
  for (int k = 0; k < 5; ++k)
    for (int j = 0; j < 5; ++j)
      for (int i = 0; i < 5; ++i) v.values[v.lattice.index(i, j, k)] = static_cast<float>(k);
  const io::SceneFrame frame(kLat0, kLon0);
  const GroundFunction ground = [](double lat, double lon) { return 1000.0 + 5000.0 * (lat - kLat0) + 3000.0 * (lon - kLon0); };
  const LatticeMapper mapper(v, frame, ground);
  const Mesh m = isosurface(v, mapper, 2.5f, {1, 2, 3, 4});
  expect_valid(m);
  EXPECT_EQ(m.triangle_count(), 2u * 4 * 4);
  for (const glm::dvec3& p : m.vertices) {
    const io::Geodetic g = frame.to_geodetic({p.x, p.y, p.z});
    EXPECT_NEAR(g.h - ground(g.lat, g.lon), 100.0 + 2.5 * 50.0, 1e-3);
  }
}

TEST(Isosurface, DefaultColoursAreDistinctAndCycle) {
  std::set<std::array<int, 3>> seen;
  for (std::size_t i = 0; i < 5; ++i) {
    const glm::u8vec3 c = default_isosurface_color(i);
    seen.insert({c.r, c.g, c.b});
  }
  EXPECT_EQ(seen.size(), 5u);
  EXPECT_EQ(default_isosurface_color(5), default_isosurface_color(0));
}

// CIE L*a*b* (D65) of an sRGB colour through VTK's conversion (vtkMath), not ours.
std::array<double, 3> lab_of(glm::u8vec3 c) {
  std::array<double, 3> lab{};
  vtkMath::RGBToLab(c.r / 255.0, c.g / 255.0, c.b / 255.0, &lab[0], &lab[1], &lab[2]);
  return lab;
}

double delta_e(glm::u8vec3 a, glm::u8vec3 b) {
  const auto p = lab_of(a), q = lab_of(b);
  return std::hypot(p[0] - q[0], p[1] - q[1], p[2] - q[2]);
}

TEST(Isosurface, DefaultColoursAreFarFromEveryColourOfEverySliceMapAndFromEachOther) {
  for (std::size_t i = 0; i < 5; ++i) {
    const glm::u8vec3 c = default_isosurface_color(i);
    for (const std::string& name : colormap_names()) {
      const Colormap map = colormap_by_name(name);
      double nearest = 1e9;
      for (int k = 0; k <= 1024; ++k) nearest = std::min(nearest, delta_e(c, map.map(k / 1024.0)));
      EXPECT_GE(nearest, 25.0) << "colour " << i << " against " << name;
    }
    for (std::size_t j = 0; j < i; ++j) EXPECT_GE(delta_e(c, default_isosurface_color(j)), 60.0) << i << " and " << j;
  }
}

TEST(Geometry, AppendOffsetsTheIndices) {
  Mesh a{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{1, 1, 1, 1}, {1, 1, 1, 1}, {1, 1, 1, 1}}, {0, 1, 2}};
  const Mesh b{{{0, 0, 5}, {1, 0, 5}, {0, 1, 5}}, {{2, 2, 2, 2}, {2, 2, 2, 2}, {2, 2, 2, 2}}, {2, 1, 0}};
  append(a, b);
  EXPECT_EQ(a.vertices.size(), 6u);
  EXPECT_EQ(a.colors[4], glm::u8vec4(2, 2, 2, 2));
  EXPECT_EQ(a.triangles, (std::vector<std::uint32_t>{0, 1, 2, 5, 4, 3}));
}

// ---- Slices ------------------------------------------------------------------------------

TEST(Slice, ConstantLatitudeSheetLiesOnItsParallel) {
  Scene s(geographic_volume({20, 15, 10}));
  const auto& l = s.volume.lattice;
  SliceSpec spec;
  spec.kind = SliceKind::kLat;
  spec.value = l.origin[1] + 6.3 * l.spacing[1];
  const Mesh m = slice(s.volume, s.mapper, spec, {});
  expect_valid(m);
  EXPECT_EQ(m.vertices.size(), 20u * 10u);
  EXPECT_EQ(m.triangle_count(), 2u * 19u * 9u);
  double xmin = INFINITY, xmax = -INFINITY;
  for (const glm::dvec3& p : m.vertices) {
    EXPECT_NEAR(p.y, s.frame.y_of_lat(spec.value), 1e-6);
    xmin = std::min(xmin, p.x);
    xmax = std::max(xmax, p.x);
  }
  EXPECT_NEAR(xmin, s.frame.x_of_lon(l.origin[0]), 1e-6);
  EXPECT_NEAR(xmax, s.frame.x_of_lon(l.world(0, 19)), 1e-6);
}

TEST(Slice, ConstantLongitudeSheetLiesOnItsMeridian) {
  Scene s(geographic_volume({20, 15, 10}));
  SliceSpec spec;
  spec.kind = SliceKind::kLon;
  spec.value = s.volume.lattice.world(0, 11.75);
  const Mesh m = slice(s.volume, s.mapper, spec, {});
  expect_valid(m);
  EXPECT_EQ(m.triangle_count(), 2u * 14u * 9u);
  for (const glm::dvec3& p : m.vertices) EXPECT_NEAR(p.x, s.frame.x_of_lon(spec.value), 1e-6);
}

TEST(Slice, AltitudeSheetIsAtThatHeight) {
  Scene s(geographic_volume({20, 15, 10}));
  const SliceSpec spec = at(SliceKind::kAlt, 333.0);
  const Mesh m = slice(s.volume, s.mapper, spec, {});
  expect_valid(m);
  EXPECT_EQ(m.triangle_count(), 2u * 19u * 14u);
  for (const glm::dvec3& p : m.vertices) EXPECT_NEAR(s.frame.to_geodetic({p.x, p.y, p.z}).h, 333.0, 1e-6);
}

TEST(Slice, AglSheetFollowsTheGroundInADatumVolume) {
  Volume v = geographic_volume({30, 30, 40});  // heights 100 .. 2050 m
  Scene s(std::move(v));
  const SliceSpec spec = at(SliceKind::kAgl, 300.0);
  const Mesh m = slice(s.volume, s.mapper, spec, hills);
  expect_valid(m);
  EXPECT_EQ(m.triangle_count(), 2u * 29u * 29u);
  for (const glm::dvec3& p : m.vertices) {
    const io::Geodetic g = s.frame.to_geodetic({p.x, p.y, p.z});
    EXPECT_NEAR(g.h - hills(g.lat, g.lon), 300.0, 1e-6);
  }
}

TEST(Slice, HeightsConvertInATerrainFollowingVolume) {
  Scene s(geographic_volume({30, 30, 10}, HeightRef::kGround), hills);  // 100 .. 550 m above ground
  // agl: a constant lattice height; every column crosses it.
  const Mesh agl = slice(s.volume, s.mapper, at(SliceKind::kAgl, 222.0), hills);
  expect_valid(agl);
  EXPECT_EQ(agl.triangle_count(), 2u * 29u * 29u);
  for (const glm::dvec3& p : agl.vertices) {
    const io::Geodetic g = s.frame.to_geodetic({p.x, p.y, p.z});
    EXPECT_NEAR(g.h - hills(g.lat, g.lon), 222.0, 1e-6);
  }
  // alt: 1000 m above the datum is inside the volume only where the ground is 450 .. 900 m.
  const Mesh alt = slice(s.volume, s.mapper, at(SliceKind::kAlt, 1000.0), hills);
  expect_valid(alt);
  EXPECT_GT(alt.triangle_count(), 0u);
  EXPECT_LT(alt.triangle_count(), 2u * 29u * 29u);
  for (const glm::dvec3& p : alt.vertices) {
    const io::Geodetic g = s.frame.to_geodetic({p.x, p.y, p.z});
    EXPECT_NEAR(g.h, 1000.0, 1e-6);
    EXPECT_GE(g.h - hills(g.lat, g.lon), 100.0 - 1e-6);
    EXPECT_LE(g.h - hills(g.lat, g.lon), 550.0 + 1e-6);
  }
}

// Seeded ENU volumes: the crossings are found by iteration, to 1e-11 degrees and 1e-6 m.
TEST(Slice, EnuVolumesSliceOnParallelsMeridiansAndHeights) {
  std::mt19937 rng(9001);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const io::SceneFrame frame(kLat0, kLon0);
  for (int trial = 0; trial < 6; ++trial) {
    const double cell = 100.0 + 200.0 * u(rng);
    Volume v = make_volume({25, 25, 12}, FrameKind::kEnu, HeightRef::kDatum,
                           {-12.0 * cell + 1000.0 * (u(rng) - 0.5), -12.0 * cell, -200.0}, {cell, cell, 100.0});
    const LatticeMapper mapper(v, frame);
    const io::Geodetic sw = mapper.geodetic(0, 0, 0), ne = mapper.geodetic(24, 24, 0);
    const double lat = sw.lat + (ne.lat - sw.lat) * (0.1 + 0.8 * u(rng));
    const double lon = sw.lon + (ne.lon - sw.lon) * (0.1 + 0.8 * u(rng));
    const double alt = 400.0 + 800.0 * u(rng);  // the lattice spans 300 .. 1400 m (origin 500 m)
    const Mesh mlat = slice(v, mapper, at(SliceKind::kLat, lat), {});
    const Mesh mlon = slice(v, mapper, at(SliceKind::kLon, lon), {});
    const Mesh malt = slice(v, mapper, at(SliceKind::kAlt, alt), {});
    for (const Mesh* m : {&mlat, &mlon, &malt}) {
      expect_valid(*m);
      EXPECT_GT(m->triangle_count(), 100u) << "trial " << trial;
    }
    for (const glm::dvec3& p : mlat.vertices) EXPECT_NEAR(p.y, frame.y_of_lat(lat), 1e-5) << "trial " << trial;
    for (const glm::dvec3& p : mlon.vertices) EXPECT_NEAR(p.x, frame.x_of_lon(lon), 1e-5) << "trial " << trial;
    for (const glm::dvec3& p : malt.vertices) EXPECT_NEAR(frame.to_geodetic({p.x, p.y, p.z}).h, alt, 1e-5);
  }
}

TEST(Slice, ColoursFollowTheMapAtKnownValues) {
  Scene s(geographic_volume({11, 6, 5}));
  for (int k = 0; k < 5; ++k)
    for (int j = 0; j < 6; ++j)
      for (int i = 0; i < 11; ++i) s.volume.values[s.volume.lattice.index(i, j, k)] = -150.0f + 10.0f * i;
  const Colormap plasma = colormap_by_name("plasma");
  SliceSpec spec = at(SliceKind::kLat, s.volume.lattice.world(1, 2.5));
  spec.colormap = "plasma";
  spec.opacity = 0.4;
  // Default range: the volume's, -150 .. -50.
  Mesh m = slice(s.volume, s.mapper, spec, {});
  expect_valid(m);
  for (std::size_t n = 0; n < m.vertices.size(); ++n) {
    const double i = std::round(lattice_of(s.volume, s.frame, m.vertices[n]).x);
    EXPECT_EQ(m.colors[n], glm::u8vec4(plasma.map(i / 10.0), 102)) << "i=" << i;
  }
  // An explicit range clamps outside it.
  spec.lo = -120.0f;
  spec.hi = -100.0f;
  m = slice(s.volume, s.mapper, spec, {});
  for (std::size_t n = 0; n < m.vertices.size(); ++n) {
    const double value = -150.0 + 10.0 * std::round(lattice_of(s.volume, s.frame, m.vertices[n]).x);
    const double t = std::clamp((value + 120.0) / 20.0, 0.0, 1.0);
    EXPECT_EQ(m.colors[n], glm::u8vec4(plasma.map(t), 102)) << "value=" << value;
  }
}

// A categorical slice (best_server) shows each vertex's nearest lattice value, never one
// interpolated between two categories, in that category's colour: seeded indices 1..25 against
// the nearest point found by rounding the vertex's lattice coordinates, and tab20's colours
// written out here from matplotlib's hex codes (darks, then lights, cycled after 20).
TEST(Slice, CategoricalShowsTheNearestLatticeValueInItsCategoryColour) {
  const char* tab20[] = {"1f77b4", "ff7f0e", "2ca02c", "d62728", "9467bd", "8c564b", "e377c2",
                         "7f7f7f", "bcbd22", "17becf", "aec7e8", "ffbb78", "98df8a", "ff9896",
                         "c5b0d5", "c49c94", "f7b6d2", "c7c7c7", "dbdb8d", "9edae5"};
  auto expected = [&](int k) {
    const unsigned long rgb = std::stoul(tab20[(k - 1) % 20], nullptr, 16);
    return glm::u8vec4((rgb >> 16) & 255, (rgb >> 8) & 255, rgb & 255, 255);
  };
  std::mt19937 rng(4242);
  std::uniform_int_distribution<int> category(1, 25);
  Scene s(geographic_volume({9, 7, 6}));
  for (float& x : s.volume.values) x = static_cast<float>(category(rng));
  const SliceSpec specs[] = {at(SliceKind::kLat, s.volume.lattice.world(1, 2.3)),
                             at(SliceKind::kLon, s.volume.lattice.world(0, 5.8)),
                             at(SliceKind::kAlt, s.volume.lattice.world(2, 1.6))};
  for (SliceSpec spec : specs) {
    spec.colormap = "categorical";
    spec.opacity = 1.0;
    const Mesh m = slice(s.volume, s.mapper, spec, {});
    ASSERT_FALSE(m.empty());
    for (std::size_t n = 0; n < m.vertices.size(); ++n) {
      const glm::dvec3 q = lattice_of(s.volume, s.frame, m.vertices[n]);
      const int k = static_cast<int>(
          s.volume.values[s.volume.lattice.index(static_cast<int>(std::round(q.x)), static_cast<int>(std::round(q.y)),
                                                 static_cast<int>(std::round(q.z)))]);
      EXPECT_EQ(m.colors[n], expected(k)) << "vertex " << n << " at " << q.x << ", " << q.y << ", " << q.z;
    }
  }
  EXPECT_EQ(parse_slice("agl=30,colormap=categorical").colormap, "categorical");
}

// Seeded linear fields are reproduced exactly by the trilinear interpolation (read through the
// grey map, to within its 8-bit rounding).
TEST(Slice, InterpolationIsExactOnLinearFields) {
  std::mt19937 rng(31337);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 10; ++trial) {
    Scene s(geographic_volume({12, 9, 7}), hills);
    const double c0 = 50.0 * u(rng), ci = 3.0 * u(rng), cj = 3.0 * u(rng), ck = 3.0 * u(rng);
    for (int k = 0; k < 7; ++k)
      for (int j = 0; j < 9; ++j)
        for (int i = 0; i < 12; ++i)
          s.volume.values[s.volume.lattice.index(i, j, k)] = static_cast<float>(c0 + ci * i + cj * j + ck * k);
    const float lo = static_cast<float>(c0 - 100.0), hi = static_cast<float>(c0 + 100.0);  // beyond the field
    const SliceKind kinds[] = {SliceKind::kLat, SliceKind::kLon, SliceKind::kAlt};
    const double values[] = {s.volume.lattice.world(1, 0.5 + 7.0 * (u(rng) + 1.0) / 2.0),
                             s.volume.lattice.world(0, 0.5 + 10.0 * (u(rng) + 1.0) / 2.0),
                             s.volume.lattice.world(2, 0.5 + 5.0 * (u(rng) + 1.0) / 2.0)};
    for (int n = 0; n < 3; ++n) {
      SliceSpec spec = at(kinds[n], values[n]);
      spec.colormap = "grey";
      spec.opacity = 1.0;
      spec.lo = lo;
      spec.hi = hi;
      const Mesh m = slice(s.volume, s.mapper, spec, hills);
      ASSERT_FALSE(m.empty());
      for (std::size_t v = 0; v < m.vertices.size(); ++v) {
        const glm::dvec3 q = lattice_of(s.volume, s.frame, m.vertices[v]);
        const double value = c0 + ci * q.x + cj * q.y + ck * q.z;
        const double grey = 255.0 * (value - lo) / (hi - lo);
        EXPECT_NEAR(m.colors[v].r, grey, 1.0) << "trial " << trial << " kind " << n;
        EXPECT_EQ(m.colors[v].a, 255);
      }
    }
  }
}

TEST(Slice, NanPointsDropTheCellsAroundThem) {
  Scene s(geographic_volume({10, 8, 6}));
  const std::size_t full = 2u * 9u * 5u;
  const SliceSpec on_plane = at(SliceKind::kLat, s.volume.lattice.world(1, 3.0));
  const SliceSpec between = at(SliceKind::kLat, s.volume.lattice.world(1, 3.4));
  s.volume.values[s.volume.lattice.index(4, 3, 2)] = std::nanf("");  // an interior point of plane j = 3
  EXPECT_EQ(slice(s.volume, s.mapper, on_plane, {}).triangle_count(), full - 2u * 4u);
  EXPECT_EQ(slice(s.volume, s.mapper, between, {}).triangle_count(), full - 2u * 4u);
  s.volume.values[s.volume.lattice.index(0, 4, 0)] = std::nanf("");  // a corner of plane j = 4
  EXPECT_EQ(slice(s.volume, s.mapper, on_plane, {}).triangle_count(), full - 2u * 4u);  // weight 0
  EXPECT_EQ(slice(s.volume, s.mapper, between, {}).triangle_count(), full - 2u * 5u);
}

TEST(Slice, OutsideTheVolumeThrowsOneLineNamingTheExtent) {
  Scene s(geographic_volume({10, 8, 6}), hills);  // lat 45.49 .. 45.4939, heights 100 .. 350 m
  const std::pair<SliceSpec, std::string> cases[] = {
      {at(SliceKind::kLat, 45.6), "slice lat=45.6 lies outside the volume 'test_field' (latitude 45.49 .. 45.4939 degrees)"},
      {at(SliceKind::kLon, 6.0), "(longitude 6.49 .. 6.4975 degrees)"},
      {at(SliceKind::kAlt, 351.0), "(height above the datum 100 .. 350 m)"},
      {at(SliceKind::kAgl, 50.0), "(height above ground "},  // the ground is above the volume
  };
  for (const auto& [spec, message] : cases) {
    try {
      slice(s.volume, s.mapper, spec, hills);
      ADD_FAILURE() << "no exception for " << message;
    } catch (const std::invalid_argument& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(message), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  }
}

TEST(Slice, BadSpecsThrow) {
  Scene s(geographic_volume({10, 8, 6}));
  SliceSpec unknown_map = at(SliceKind::kAlt, 200.0);
  unknown_map.colormap = "nope";
  EXPECT_THROW(slice(s.volume, s.mapper, unknown_map, {}), std::invalid_argument);
  SliceSpec too_opaque = at(SliceKind::kAlt, 200.0);
  too_opaque.opacity = 1.5;
  EXPECT_THROW(slice(s.volume, s.mapper, too_opaque, {}), std::invalid_argument);
  EXPECT_THROW(slice(s.volume, s.mapper, at(SliceKind::kAlt, NAN), {}), std::invalid_argument);
  EXPECT_THROW(slice(s.volume, s.mapper, at(SliceKind::kAgl, 200.0), {}), std::invalid_argument);
}

// ---- Parsers -----------------------------------------------------------------------------

TEST(ParseSlice, AcceptsTheDocumentedForms) {
  const SliceSpec a = parse_slice("agl=300");
  EXPECT_EQ(a.kind, SliceKind::kAgl);
  EXPECT_EQ(a.value, 300.0);
  EXPECT_EQ(a.colormap, "viridis");
  EXPECT_EQ(a.opacity, 0.5);
  EXPECT_FALSE(a.lo);
  EXPECT_FALSE(a.hi);
  EXPECT_EQ(parse_slice("lat=44.2").kind, SliceKind::kLat);
  EXPECT_EQ(parse_slice("lon=-71.4").value, -71.4);
  const SliceSpec b = parse_slice("alt=2500,colormap=plasma,opacity=0.4,range=-140:-60");
  EXPECT_EQ(b.kind, SliceKind::kAlt);
  EXPECT_EQ(b.value, 2500.0);
  EXPECT_EQ(b.colormap, "plasma");
  EXPECT_EQ(b.opacity, 0.4);
  EXPECT_EQ(b.lo, -140.0f);
  EXPECT_EQ(b.hi, -60.0f);
  const SliceSpec c = parse_slice("colormap=gray,range=:-60,lat=44");
  EXPECT_EQ(c.colormap, "grey");
  EXPECT_FALSE(c.lo);
  EXPECT_EQ(c.hi, -60.0f);
}

TEST(ParseSlice, ErrorsAreOneLineAndNameTheBadPart) {
  const std::pair<const char*, const char*> cases[] = {
      {"", "slice '': '' is not KEY=VALUE"},
      {"agl", "slice 'agl': 'agl' is not KEY=VALUE"},
      {"agl=abc", "agl 'abc' is not a number"},
      {"agl=300,", "'' is not KEY=VALUE"},
      {"foo=1,agl=3", "unknown key 'foo'"},
      {"colormap=plasma", "no position"},
      {"agl=300,lat=44", "'lat=44': give one of lat, lon, alt, agl only"},
      {"lat=95", "lat '95' is not a valid latitude"},
      {"agl=300,opacity=2", "opacity '2' is not within [0, 1]"},
      {"agl=300,opacity=0.5,opacity=0.4", "opacity is given twice"},
      {"agl=300,colormap=nope", "unknown colour map 'nope' (known: viridis"},
      {"agl=300,range=5", "range '5' is not LO:HI"},
      {"agl=300,range=5:1", "range '5:1' needs LO < HI"},
      {"agl=300,range=a:1", "range low end 'a' is not a number"},
      {"agl=inf", "agl 'inf' is not a number"},
  };
  for (const auto& [text, message] : cases) {
    try {
      parse_slice(text);
      ADD_FAILURE() << "no exception for '" << text << "'";
    } catch (const std::invalid_argument& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind("slice '" + std::string(text) + "': ", 0), 0u) << what;
      EXPECT_NE(what.find(message), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  }
}

TEST(ParseIsosurface, AcceptsTheDocumentedForms) {
  const IsoSpec a = parse_isosurface("120", 2);
  EXPECT_EQ(a.value, 120.0f);
  EXPECT_EQ(a.color, default_isosurface_color(2));
  EXPECT_EQ(a.opacity, 0.5);
  const IsoSpec b = parse_isosurface("120,color=255:200:0,opacity=0.4");
  EXPECT_EQ(b.color, glm::u8vec3(255, 200, 0));
  EXPECT_EQ(b.opacity, 0.4);
  EXPECT_EQ(b.rgba(), glm::u8vec4(255, 200, 0, 102));
  EXPECT_EQ(parse_isosurface("-95.5,colour=#10a0Ff").color, glm::u8vec3(0x10, 0xa0, 0xff));
  EXPECT_EQ(parse_isosurface("-95.5").value, -95.5f);
}

TEST(ParseIsosurface, ErrorsAreOneLineAndNameTheBadPart) {
  const std::pair<const char*, const char*> cases[] = {
      {"", "value '' is not a number"},
      {"abc", "value 'abc' is not a number"},
      {"1e39", "value '1e39' is out of range"},
      {"120,color=300:0:0", "color '300:0:0': '300' is not an integer in [0, 255]"},
      {"120,color=1:2", "color '1:2' is not R:G:B or #RRGGBB"},
      {"120,color=#12345", "color '#12345' is not #RRGGBB"},
      {"120,opacity=-1", "opacity '-1' is not within [0, 1]"},
      {"120,opacity=x", "opacity 'x' is not a number"},
      {"120,size=3", "unknown key 'size' (known: color, opacity)"},
      {"120,0.4", "'0.4' is not KEY=VALUE"},
  };
  for (const auto& [text, message] : cases) {
    try {
      parse_isosurface(text);
      ADD_FAILURE() << "no exception for '" << text << "'";
    } catch (const std::invalid_argument& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind("isosurface '" + std::string(text) + "': ", 0), 0u) << what;
      EXPECT_NE(what.find(message), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  }
}

// ---- On a propagation volume over the bundled DEM -------------------------------------------

// Bilinear ground height over a geographic grid (row 0 north).
GroundFunction bilinear_ground(const io::Grid& g) {
  return [&g](double lat, double lon) { return volume::dem_height(g, lat, lon); };
}

TEST(Geometry, PropagationVolumeOverTheBundledDem) {
  const auto path = std::filesystem::path(TERRAVOL_SOURCE_DIR) / "data" / "dem" / "N45E006.hgt";
  const io::Grid dem = io::read_dem(path);
  RfGrid grid;
  grid.radius_km = 4.0;
  grid.spacing_arcsec = 9.0;
  grid.heights_agl = {0.0, 100.0, 200.0, 300.0, 400.0, 500.0};
  const Volume v = compute_rf(dem, Transmitter{45.5, 6.5, 30.0, 900.0, std::nullopt, {}, {}}, grid).path_loss;
  const GroundFunction ground = bilinear_ground(dem);
  const io::SceneFrame frame(45.5, 6.5);
  const LatticeMapper mapper(v, frame, ground);

  const Mesh iso = isosurface(v, mapper, 120.0f, parse_isosurface("120").rgba());
  expect_valid(iso);
  EXPECT_GT(iso.triangle_count(), 100u);
  for (const glm::dvec3& p : iso.vertices) {
    const io::Geodetic g = frame.to_geodetic({p.x, p.y, p.z});
    EXPECT_GE(g.h - ground(g.lat, g.lon), -1e-3);
    EXPECT_LE(g.h - ground(g.lat, g.lon), 500.0 + 1e-3);
  }
  const SliceSpec spec = parse_slice("agl=250,colormap=turbo,opacity=0.5");
  const Mesh agl = slice(v, mapper, spec, ground);
  expect_valid(agl);
  EXPECT_EQ(agl.triangle_count(), 2u * (v.lattice.dims[0] - 1u) * (v.lattice.dims[1] - 1u));
  for (const glm::dvec3& p : agl.vertices) {
    const io::Geodetic g = frame.to_geodetic({p.x, p.y, p.z});
    EXPECT_NEAR(g.h - ground(g.lat, g.lon), 250.0, 1e-6);
  }
}

}  // namespace
}  // namespace terravol::volume
