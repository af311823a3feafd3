// The volume layer's legend (app/scene/volume_layer.h) for a categorical slice: one swatch per
// transmitter the volume records, named, in tab20's colours (written out here as matplotlib's
// hex codes), or the whole numbers of the volume's range when it records none.
#include "app/scene/volume_layer.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "io/mosaic.h"
#include "io/scene_frame.h"
#include "temp_dir.h"
#include "volume/geometry.h"
#include "volume/vdb_write.h"

namespace terravol::app::scene {
namespace {

// A 5 x 4 x 3 index volume (values 1..3) over the bundled DEM (N45E006), heights above ground.
volume::Volume index_volume() {
  volume::Volume v;
  v.name = "best_server";
  v.frame.kind = volume::FrameKind::kGeographic;
  v.frame.height = volume::HeightRef::kGround;
  v.lattice.dims = {5, 4, 3};
  v.lattice.origin = {6.50, 45.50, 0.0};
  v.lattice.spacing = {0.01, 0.01, 100.0};
  v.values.resize(v.lattice.size());
  for (std::size_t n = 0; n < v.values.size(); ++n) v.values[n] = static_cast<float>(1 + n % 3);
  v.active_points = v.values.size();
  return v;
}

Legend legend_of(const volume::Volume& v, const test::TempDir& dir) {
  const auto file = dir.path() / "index.vdb";
  volume::write_vdb(file, {&v}, true);
  VolumeSpec spec;
  spec.file = file;
  volume::SliceSpec s = volume::parse_slice("agl=100,colormap=categorical");
  spec.slices.push_back(s);
  const io::Mosaic mosaic = io::Mosaic::open({std::string(TERRAVOL_SOURCE_DIR) + "/data/dem/N45E006.hgt"});
  return VolumeLayer({spec}, mosaic, io::SceneFrame(45.515, 6.52)).legend();
}

TEST(VolumeLayerLegend, CategoricalSliceNamesTheRecordedTransmittersInTheirColours) {
  const test::TempDir dir;
  volume::Volume v = index_volume();
  v.attributes["transmitters"] = "west,45.51,6.51,30;east,45.52,6.53,30;north,45.53,6.52,20";
  const Legend l = legend_of(v, dir);
  ASSERT_EQ(l.categories.size(), 3u);
  EXPECT_EQ(l.categories_title, "transmitters");
  EXPECT_TRUE(l.colormap.empty());
  const std::vector<std::string> names{"west", "east", "north"};
  const std::vector<Rgb> colours{{0x1f, 0x77, 0xb4}, {0xff, 0x7f, 0x0e}, {0x2c, 0xa0, 0x2c}};
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(l.categories[k].label, names[k]);
    EXPECT_EQ(l.categories[k].color, colours[k]);
    EXPECT_EQ(l.categories[k].value, static_cast<double>(k + 1));
  }
}

TEST(VolumeLayerLegend, CategoricalSliceWithoutTransmittersCountsTheRange) {
  const test::TempDir dir;
  const Legend l = legend_of(index_volume(), dir);
  ASSERT_EQ(l.categories.size(), 3u);
  EXPECT_EQ(l.categories_title, "categories");
  for (std::size_t k = 0; k < 3; ++k) EXPECT_EQ(l.categories[k].label, std::to_string(k + 1));
  EXPECT_EQ(l.categories[2].color, (Rgb{0x2c, 0xa0, 0x2c}));
}

// Two volumes of one field, each with isosurfaces: the legend lists all of them, each named by
// its volume's file; a hidden volume's are left out.
TEST(VolumeLayerLegend, IsosurfacesOfEveryVisibleVolumeOfTheFieldAreListedByFile) {
  const test::TempDir dir;
  volume::Volume v = index_volume();
  v.name = "path_loss_db";
  v.units = "dB";
  std::vector<VolumeSpec> specs;
  for (const char* name : {"west.vdb", "east.vdb", "hidden.vdb"}) {
    volume::write_vdb(dir.path() / name, {&v}, true);
    VolumeSpec spec;
    spec.file = dir.path() / name;
    volume::IsoSpec iso;
    iso.value = 1.5f;
    spec.isosurfaces = {iso};
    spec.visible = std::string(name) != "hidden.vdb";
    specs.push_back(spec);
  }
  specs[1].isosurfaces.push_back(specs[1].isosurfaces.front());
  specs[1].isosurfaces.back().value = 2.5f;
  const io::Mosaic mosaic = io::Mosaic::open({std::string(TERRAVOL_SOURCE_DIR) + "/data/dem/N45E006.hgt"});
  const Legend l = VolumeLayer(specs, mosaic, io::SceneFrame(45.515, 6.52)).legend();
  EXPECT_EQ(l.title, "path_loss_db (dB)");
  ASSERT_EQ(l.levels.size(), 3u);
  EXPECT_EQ(l.levels[0].label, "west: 1.5 dB");
  EXPECT_EQ(l.levels[1].label, "east: 1.5 dB");
  EXPECT_EQ(l.levels[2].label, "east: 2.5 dB");
}

}  // namespace
}  // namespace terravol::app::scene
