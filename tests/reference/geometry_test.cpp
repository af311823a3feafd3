// The reference's geometry: placement from the frame's definition, isosurfaces by VTK's flying
// edges, slices by its own crossing code; exact tiny cases on lattices built here.
#include <GeographicLib/LocalCartesian.hpp>
#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>

#include "reference/geometry.h"
#include "volume/colormap.h"

namespace terravol::reference {
namespace {

namespace fs = std::filesystem;

volume::Volume lattice(volume::VolumeFrame frame, std::array<int, 3> dims, std::array<double, 3> origin,
                       std::array<double, 3> spacing, const std::function<float(int, int, int)>& f) {
  volume::Volume v;
  v.name = "test";
  v.frame = frame;
  v.lattice.dims = dims;
  v.lattice.origin = origin;
  v.lattice.spacing = spacing;
  v.values.resize(v.lattice.size());
  for (int k = 0; k < dims[2]; ++k)
    for (int j = 0; j < dims[1]; ++j)
      for (int i = 0; i < dims[0]; ++i) v.values[v.lattice.index(i, j, k)] = f(i, j, k);
  return v;
}

volume::VolumeFrame geographic(volume::HeightRef h = volume::HeightRef::kDatum) {
  volume::VolumeFrame f;
  f.kind = volume::FrameKind::kGeographic;
  f.height = h;
  return f;
}

const Dem& bundled() {
  static const Dem d = Dem::read({fs::path(TERRAVOL_SOURCE_DIR) / "data" / "dem" / "N45E006.hgt"}, {45, 46, 6, 7});
  return d;
}

TEST(Placement, GeographicLatticePointsGoThroughTheFrame) {
  const Frame frame(45.5, 6.5);
  const auto v = lattice(geographic(), {4, 3, 2}, {6.4, 45.45, 100.0}, {0.01, 0.02, 50.0}, [](int, int, int) { return 0.f; });
  const Placement p(v, frame, nullptr);
  const glm::dvec3 a = p.scene(2, 1, 1), b = frame.to_scene(45.47, 6.42, 150.0);
  EXPECT_NEAR(a.x, b.x, 1e-9);
  EXPECT_NEAR(a.y, b.y, 1e-9);
  EXPECT_NEAR(a.z, b.z, 1e-9);
}

TEST(Placement, HeightsAboveTheGroundAddTheBilinearGround) {
  const Frame frame(45.5, 6.5);
  const auto v = lattice(geographic(volume::HeightRef::kGround), {5, 5, 3}, {6.45, 45.45, 0.0}, {0.013, 0.011, 100.0},
                         [](int, int, int) { return 0.f; });
  EXPECT_THROW(Placement(v, frame, nullptr), std::invalid_argument);
  const Placement p(v, frame, &bundled());
  const Geodetic g = p.geodetic(1.5, 2.25, 2);
  EXPECT_DOUBLE_EQ(g.lon, 6.45 + 1.5 * 0.013);
  EXPECT_DOUBLE_EQ(g.lat, 45.45 + 2.25 * 0.011);
  EXPECT_NEAR(g.h, 200.0 + bundled().height(g.lat, g.lon), 1e-9);
  EXPECT_NEAR(p.above_ground(g), 200.0, 1e-9);
}

TEST(Placement, EnuLatticePointsAreGeographicLibsLocalCartesian) {
  volume::VolumeFrame f;
  f.kind = volume::FrameKind::kEnu;
  f.origin_lat = 45.5;
  f.origin_lon = 6.5;
  f.origin_h = 1900;
  const auto v = lattice(f, {3, 3, 3}, {-1000, -2000, 0}, {1000, 2000, 500}, [](int, int, int) { return 0.f; });
  const Placement p(v, Frame(45.4, 6.4), nullptr);
  const GeographicLib::LocalCartesian lc(45.5, 6.5, 1900);
  const Geodetic g = p.geodetic(2, 0.5, 1);
  double e = 0, n = 0, u = 0;
  lc.Forward(g.lat, g.lon, g.h, e, n, u);
  EXPECT_NEAR(e, 1000, 1e-6);
  EXPECT_NEAR(n, -1000, 1e-6);
  EXPECT_NEAR(u, 500, 1e-6);
}

TEST(Isosurface, OfAFieldGrowingEastIsAMeridianPlaneInTheFrame) {
  const Frame frame(45.5, 6.5);
  const auto v = lattice(geographic(), {6, 5, 4}, {6.40, 45.45, 0.0}, {0.02, 0.02, 200.0},
                         [](int i, int, int) { return static_cast<float>(i); });
  const Placement p(v, frame, nullptr);
  const Mesh m = isosurface(v, p, {3.5f, {10, 20, 30}, 0.4});
  ASSERT_EQ(m.triangle_count(), 2u * 4 * 3);  // two per cell of the crossed sheet
  const double x = frame.to_scene(45.5, 6.40 + 3.5 * 0.02, 0).x;  // x depends on longitude alone
  for (std::size_t n = 0; n < m.vertices.size(); ++n) {
    EXPECT_NEAR(m.vertices[n].x, x, 1e-6);
    EXPECT_EQ(m.colors[n], glm::u8vec4(10, 20, 30, 102));  // alpha = round(0.4 * 255)
  }
}

TEST(Isosurface, DropsExactlyTheTrianglesOfCellsWithANaNCorner) {
  const Frame frame(45.5, 6.5);
  auto height = [](int, int, int k) { return static_cast<float>(k); };
  const auto whole = lattice(geographic(), {6, 6, 4}, {6.4, 45.4, 0.0}, {0.01, 0.01, 100.0}, height);
  auto holed = whole;
  holed.values[holed.lattice.index(2, 2, 1)] = std::numeric_limits<float>::quiet_NaN();
  const Placement p(whole, frame, nullptr);
  const std::size_t all = isosurface(whole, p, {1.5f, {0, 0, 0}, 1.0}).triangle_count();
  EXPECT_EQ(all, 2u * 5 * 5);
  EXPECT_EQ(isosurface(holed, p, {1.5f, {0, 0, 0}, 1.0}).triangle_count(), all - 2 * 4);  // 4 cells share the point
  EXPECT_EQ(isosurface(whole, p, {9.0f, {0, 0, 0}, 1.0}).triangle_count(), 0u);  // not crossed
}

TEST(Slice, AglOfATerrainFollowingLatticeIsALatticeLayer) {
  const Frame frame(45.5, 6.5);
  const auto v = lattice(geographic(volume::HeightRef::kGround), {7, 6, 5}, {6.45, 45.45, 0.0}, {0.01, 0.01, 100.0},
                         [](int i, int j, int k) { return static_cast<float>(60 + 10 * k + i + j); });
  const Placement p(v, frame, &bundled());
  SliceStyle s;
  s.kind = SliceKind::kAgl;
  s.value = 200;
  s.lo = 60;
  s.hi = 120;
  const Mesh m = slice(v, p, s);
  ASSERT_EQ(m.vertices.size(), 7u * 6);
  EXPECT_EQ(m.triangle_count(), 2u * 6 * 5);
  const volume::Colormap viridis = volume::colormap_by_name("viridis");
  for (int j = 0; j < 6; ++j)
    for (int i = 0; i < 7; ++i) {
      const std::size_t n = static_cast<std::size_t>(j) * 7 + i;  // vertices row by row
      const glm::dvec3 want = p.scene(i, j, 2);
      EXPECT_NEAR(glm::distance(m.vertices[n], want), 0.0, 1e-6);
      const glm::u8vec3 c = viridis.map((80.0 + i + j - 60.0) / 60.0);
      EXPECT_EQ(m.colors[n], glm::u8vec4(c, 128));
    }
}

TEST(Slice, AglBetweenLayersInterpolatesAlongTheColumn) {
  const Frame frame(45.5, 6.5);
  const auto v = lattice(geographic(volume::HeightRef::kGround), {3, 3, 4}, {6.45, 45.45, 0.0}, {0.01, 0.01, 100.0},
                         [](int, int, int k) { return static_cast<float>(10 * k); });
  const Placement p(v, frame, &bundled());
  SliceStyle s;
  s.kind = SliceKind::kAgl;
  s.value = 125;
  s.colormap = "grey";
  const Mesh m = slice(v, p, s);  // range: the volume's 0..30, so value 12.5 maps to 5/12
  const glm::u8vec3 c = volume::colormap_by_name("grey").map(12.5 / 30.0);
  for (std::size_t n = 0; n < m.vertices.size(); ++n) {
    EXPECT_EQ(m.colors[n], glm::u8vec4(c, 128));
    EXPECT_NEAR(glm::distance(m.vertices[n], p.scene(static_cast<double>(n % 3), static_cast<double>(n / 3), 1.25)), 0.0, 1e-6);
  }
}

TEST(Slice, LatitudeSheetsLieOnTheirParallelInGeographicAndEnuFrames) {
  const Frame frame(45.5, 6.5);
  const double y = frame.to_scene(45.4567, 6.5, 0).y;  // y depends on latitude alone
  const auto geo = lattice(geographic(), {4, 9, 3}, {6.4, 45.40, 0.0}, {0.02, 0.01, 300.0},
                           [](int i, int j, int k) { return static_cast<float>(i + j + k); });
  SliceStyle s;
  s.kind = SliceKind::kLat;
  s.value = 45.4567;
  const Placement pg(geo, frame, nullptr);
  const Mesh mg = slice(geo, pg, s);
  EXPECT_EQ(mg.vertices.size(), 4u * 3);
  for (const glm::dvec3& q : mg.vertices) EXPECT_NEAR(q.y, y, 1e-6);

  volume::VolumeFrame f;
  f.kind = volume::FrameKind::kEnu;
  f.origin_lat = 45.45;
  f.origin_lon = 6.45;
  f.origin_h = 500;
  const auto enu = lattice(f, {5, 6, 3}, {-4000, -5000, 0}, {2000, 2000, 500},
                           [](int i, int j, int k) { return static_cast<float>(i * j + k); });
  const Placement pe(enu, frame, nullptr);
  const Mesh me = slice(enu, pe, s);
  EXPECT_EQ(me.vertices.size(), 5u * 3);
  for (const glm::dvec3& q : me.vertices) EXPECT_NEAR(q.y, y, 1e-4);  // 1e-11 degree
}

TEST(Slice, NaNValuesAndMissesLeaveHolesOrThrow) {
  const Frame frame(45.5, 6.5);
  auto v = lattice(geographic(), {4, 4, 3}, {6.4, 45.4, 0.0}, {0.01, 0.01, 100.0}, [](int, int, int) { return 1.f; });
  v.values[v.lattice.index(1, 1, 1)] = std::numeric_limits<float>::quiet_NaN();
  const Placement p(v, frame, nullptr);
  SliceStyle s;
  s.kind = SliceKind::kAlt;
  s.value = 150;  // between layers 1 and 2: the NaN point has weight
  EXPECT_EQ(slice(v, p, s).triangle_count(), 2u * (9 - 4));
  s.value = 200;  // on layer 2: the NaN point has none
  EXPECT_EQ(slice(v, p, s).triangle_count(), 2u * 9);
  s.value = 900;
  EXPECT_THROW(slice(v, p, s), std::invalid_argument);
  s.value = 100;
  s.colormap = "nope";
  EXPECT_THROW(slice(v, p, s), std::invalid_argument);
  s.colormap = "viridis";
  s.kind = SliceKind::kAgl;
  EXPECT_THROW(slice(v, p, s), std::invalid_argument);  // no ground given
}

}  // namespace
}  // namespace terravol::reference
