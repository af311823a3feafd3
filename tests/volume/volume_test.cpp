#include "volume/volume.h"

#include <GeographicLib/Geodesic.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

namespace terravol::volume {
namespace {

TEST(Frame, ParsesAndFormatsEveryKind) {
  for (const char* text : {"none", "geographic", "geographic-agl", "enu:44.27,-71.3,1917.5"}) {
    EXPECT_EQ(parse_frame(format_frame(parse_frame(text))), parse_frame(text)) << text;
  }
  const VolumeFrame enu = parse_frame("enu:44.27,-71.3,1917.5");
  EXPECT_EQ(enu.kind, FrameKind::kEnu);
  EXPECT_DOUBLE_EQ(enu.origin_lat, 44.27);
  EXPECT_DOUBLE_EQ(enu.origin_lon, -71.3);
  EXPECT_DOUBLE_EQ(enu.origin_h, 1917.5);
  EXPECT_EQ(parse_frame("geographic-agl").height, HeightRef::kGround);
}

TEST(Frame, RejectsMalformedText) {
  for (const char* text : {"", "geo", "enu:", "enu:1,2", "enu:1,2,3,4", "enu:a,b,c", "enu:95,0,0", "enu:1,2,nan"}) {
    EXPECT_THROW(parse_frame(text), std::invalid_argument) << text;
  }
}

TEST(Lattice, StoresXFastest) {
  Lattice l;
  l.dims = {3, 4, 5};
  EXPECT_EQ(l.size(), 60u);
  EXPECT_EQ(l.index(1, 0, 0), 1u);
  EXPECT_EQ(l.index(0, 1, 0), 3u);
  EXPECT_EQ(l.index(0, 0, 1), 12u);
  EXPECT_EQ(l.index(2, 3, 4), 59u);
}

Volume small_volume(VolumeFrame frame) {
  Volume v;
  v.name = "test";
  v.frame = frame;
  v.lattice.dims = {3, 3, 3};
  v.lattice.origin = {6.4, 45.4, 100.0};
  v.lattice.spacing = {0.1, 0.1, 50.0};
  v.values.assign(v.lattice.size(), 0.0f);
  return v;
}

TEST(LatticeMapper, GeographicPointsGoThroughTheSceneFrame) {
  const Volume v = small_volume(parse_frame("geographic"));
  const io::SceneFrame scene(45.5, 6.5);
  const LatticeMapper map(v, scene);
  for (double k : {0.0, 1.0, 2.5}) {
    const io::Geodetic g = map.geodetic(1.0, 2.0, k);
    EXPECT_DOUBLE_EQ(g.lon, 6.5);
    EXPECT_DOUBLE_EQ(g.lat, 45.6);
    EXPECT_DOUBLE_EQ(g.h, 100.0 + 50.0 * k);
    const io::ScenePoint p = map.scene(1.0, 2.0, k), q = scene.to_scene(g);
    EXPECT_EQ(p.x, q.x);
    EXPECT_EQ(p.y, q.y);
    EXPECT_EQ(p.z, q.z);
  }
  // Constant-longitude lattice planes stay scene planes x = c.
  EXPECT_EQ(map.scene(0.0, 0.0, 0.0).x, map.scene(0.0, 2.0, 2.0).x);
}

TEST(LatticeMapper, HeightsAboveGroundAddTheGround) {
  const Volume v = small_volume(parse_frame("geographic-agl"));
  const io::SceneFrame scene(45.5, 6.5);
  EXPECT_THROW(LatticeMapper(v, scene), std::invalid_argument);
  const LatticeMapper map(v, scene, [](double lat, double lon) { return 1000.0 + lat + lon; });
  const io::Geodetic g = map.geodetic(0.0, 0.0, 1.0);
  EXPECT_NEAR(g.h, 1000.0 + 45.4 + 6.4 + 150.0, 1e-9);
}

TEST(LatticeMapper, EnuOriginAndDistances) {
  Volume v = small_volume(parse_frame("enu:44.27,-71.3,500"));
  v.lattice.origin = {0.0, 0.0, 0.0};
  v.lattice.spacing = {1000.0, 1000.0, 100.0};
  const LatticeMapper map(v, io::SceneFrame(44.27, -71.3));
  const io::Geodetic o = map.geodetic(0, 0, 0);
  EXPECT_NEAR(o.lat, 44.27, 1e-12);
  EXPECT_NEAR(o.lon, -71.3, 1e-12);
  EXPECT_NEAR(o.h, 500.0, 1e-6);
  const io::Geodetic east = map.geodetic(2, 0, 0), north = map.geodetic(0, 2, 0);
  double s_east = 0.0, s_north = 0.0;
  GeographicLib::Geodesic::WGS84().Inverse(o.lat, o.lon, east.lat, east.lon, s_east);
  GeographicLib::Geodesic::WGS84().Inverse(o.lat, o.lon, north.lat, north.lon, s_north);
  EXPECT_NEAR(s_east, 2000.0, 0.5);
  EXPECT_NEAR(s_north, 2000.0, 0.5);
  EXPECT_NEAR(east.lat, 44.27, 1e-3);  // east stays at the latitude to the tangent plane's drop
  EXPECT_GT(east.h, 500.0);            // the tangent plane rises above the ellipsoid away from the origin
}

TEST(LatticeMapper, VolumeWithoutFrameCannotBePlaced) {
  const Volume v = small_volume(VolumeFrame{});
  EXPECT_THROW(LatticeMapper(v, io::SceneFrame(45.0, 6.0)), std::invalid_argument);
}

}  // namespace
}  // namespace terravol::volume
