#include <gtest/gtest.h>

#include <fstream>

#include "reference/scene.h"
#include "temp_dir.h"
#include "volume/geometry.h"

namespace terravol::reference {
namespace {

namespace fs = std::filesystem;

fs::path write(const test::TempDir& dir, const std::string& text) {
  const fs::path p = dir.path() / "scene.json";
  std::ofstream(p) << text;
  return p;
}

TEST(Scene, ReadsVolumesAndTheirStylesWithPathsFromTheFilesFolder) {
  test::TempDir dir;
  const Scene s = read_scene(write(dir, R"({"dem": "N44W072.hgt", "volumes": [
    {"file": "rf.vdb", "field": "signal_dbm", "frame": "geographic-agl",
     "isosurfaces": [{"value": 120, "color": [1, 2, 3], "opacity": 0.25}, {"value": 130}],
     "slices": [{"agl": 300, "colormap": "plasma", "opacity": 0.4, "range": [80, 160]}, {"lat": 44.2}]},
    {"file": "/abs/other.vdb", "visible": false}],
    "camera": {"lat": 44, "lon": -71, "alt": 3000}, "render": {"size": "640x360"}})"));
  ASSERT_EQ(s.dems.size(), 1u);
  EXPECT_EQ(s.dems[0], dir.path() / "N44W072.hgt");
  ASSERT_EQ(s.volumes.size(), 2u);
  const VolumeStyle& v = s.volumes[0];
  EXPECT_EQ(v.file, dir.path() / "rf.vdb");
  EXPECT_EQ(v.field, "signal_dbm");
  EXPECT_EQ(v.frame, "geographic-agl");
  ASSERT_EQ(v.isosurfaces.size(), 2u);
  EXPECT_EQ(v.isosurfaces[0].value, 120.0f);
  EXPECT_EQ(v.isosurfaces[0].color, (std::array<std::uint8_t, 3>{1, 2, 3}));
  EXPECT_EQ(v.isosurfaces[0].opacity, 0.25);
  EXPECT_EQ(v.isosurfaces[1].opacity, 0.5);  // the documented default
  const auto palette = volume::default_isosurface_color(1);  // by index within the volume
  EXPECT_EQ(v.isosurfaces[1].color, (std::array<std::uint8_t, 3>{palette.r, palette.g, palette.b}));
  ASSERT_EQ(v.slices.size(), 2u);
  EXPECT_EQ(v.slices[0].kind, SliceKind::kAgl);
  EXPECT_EQ(v.slices[0].value, 300.0);
  EXPECT_EQ(v.slices[0].colormap, "plasma");
  EXPECT_EQ(v.slices[0].lo, 80.0f);
  EXPECT_EQ(v.slices[0].hi, 160.0f);
  EXPECT_EQ(v.slices[1].kind, SliceKind::kLat);
  EXPECT_EQ(v.slices[1].colormap, "viridis");
  EXPECT_FALSE(v.slices[1].lo.has_value());
  EXPECT_EQ(s.volumes[1].file, fs::path("/abs/other.vdb"));
  EXPECT_FALSE(s.volumes[1].visible);
}

TEST(Scene, BadFilesThrowNamingTheFile) {
  test::TempDir dir;
  for (const char* text : {"{not json", R"({"volumes": [{"isosurfaces": []}]})",
                           R"({"volumes": [{"file": "a.vdb", "slices": [{"agl": 1, "lat": 2}]}]})",
                           R"({"volumes": [{"file": "a.vdb", "isosurfaces": [{"value": "x"}]}]})"}) {
    try {
      read_scene(write(dir, text));
      FAIL() << text;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("scene.json"), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(read_scene(dir.path() / "missing.json"), std::runtime_error);
}

}  // namespace
}  // namespace terravol::reference
