// RF volumes over the terrain as a user renders them: isosurfaces and slices from options and
// from a scene file, the tree's exact order against VTK's depth peeling, and bad volume input.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <string>

#include "image_compare.h"
#include "require_display.h"
#include "run_command.h"
#include "temp_dir.h"

namespace terravol {
namespace {

using test::run_terravol;

std::string bundled_dem() { return std::string(TERRAVOL_SOURCE_DIR) + "/data/dem/N45E006.hgt"; }

// Three overlapping path-loss volumes of the bundled DEM, made once by `terravol rf`.
class VolumeRender : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new test::TempDir;
    const char* tx[3] = {"45.50,6.50,30", "45.53,6.56,60", "45.46,6.55,20"};
    for (int k = 0; k < 3; ++k) {
      const auto r = run_terravol("rf --quiet --tx " + std::string(tx[k]) + " --dem " + bundled_dem() +
                                  " --radius-km 7 --heights 0:1500:100 -o " + volume(k));
      ASSERT_EQ(r.status, 0) << r.err;
    }
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  static std::string volume(int k) { return (dir_->path() / ("rf" + std::to_string(k) + ".vdb")).string(); }
  static std::filesystem::path path(const std::string& name) { return dir_->path() / name; }

  // Renders ARGS to NAME.png (--force) and reads it back. Merging three volumes takes 20 to
  // 35 s on the shared two cores under load (measured): two minutes at most.
  static test::Image render(const std::string& args, const std::string& name) {
    const auto png = path(name + ".png");
    const auto r = run_terravol("render " + args + " --force -o " + png.string(), 120);
    EXPECT_EQ(r.status, 0) << r.err;
    return test::read_png(png);
  }

  static inline test::TempDir* dir_ = nullptr;
};

// Looking north-east over the transmitters from the south-west, low enough that the surfaces
// cross the terrain and each other.
const std::string kView = " --camera 45.44,6.44,2600,40,-18 --size 480x270";

TEST_F(VolumeRender, IsosurfacesAndASliceChangeTheImageAndKeepTheTerrain) {
  TERRAVOL_REQUIRE_DISPLAY();
  const test::Image terrain = render(bundled_dem() + kView, "terrain");
  // Without the legend, whose card takes a third of a picture this small: the volume alone.
  const test::Image with = render(bundled_dem() + kView + " --volume " + volume(0) +
                                      " --iso 100,color=255:0:0,opacity=0.5 --iso 120 --slice agl=300,opacity=0.5 --no-legend",
                                  "with");
  ASSERT_EQ(terrain.width, with.width);
  const double changed = test::differing_share(terrain, with, 8);
  EXPECT_GT(changed, 0.05) << "the volume should cover part of the view";
  EXPECT_LT(changed, 0.95) << "and leave some terrain and sky as they were";
}

TEST_F(VolumeRender, TheTreeOrderMatchesExactDepthPeelingOnThreeOverlappingVolumes) {
  TERRAVOL_REQUIRE_DISPLAY();
  // Two isosurfaces each (opacity 0.3 to 0.6) and a slice through the first: the issue's scene.
  const auto scene = path("three.json");
  std::ofstream(scene) << R"({"dem": [")" << bundled_dem() << R"("], "volumes": [
    {"file": "rf0.vdb", "isosurfaces": [{"value": 100, "opacity": 0.4}, {"value": 125, "opacity": 0.3}],
     "slices": [{"agl": 400, "opacity": 0.5, "colormap": "viridis"}]},
    {"file": "rf1.vdb", "isosurfaces": [{"value": 105, "opacity": 0.6}, {"value": 120, "opacity": 0.35}]},
    {"file": "rf2.vdb", "isosurfaces": [{"value": 95, "opacity": 0.5}, {"value": 115, "opacity": 0.45}]}]})";
  const std::string args = "--scene " + scene.string() + kView;
  const test::Image bsp = render(args + " --order bsp", "bsp");
  const test::Image peel = render(args + " --order peel", "peel");
  const test::Image vtk = render(args + " --order vtk", "vtk");
  const test::Image sort = render(args + " --order sort", "sort");
  ASSERT_GT(peel.width, 0);
  for (const test::Image* image : {&bsp, &vtk, &sort}) {
    ASSERT_EQ(image->width, peel.width);
    ASSERT_EQ(image->height, peel.height);
  }
  const double bsp_error = test::differing_share(bsp, peel, 3);
  std::printf("pixels differing from depth peeling by more than 3/255: bsp %.4f%%, vtk %.2f%%, sort %.2f%%\n",
              100 * bsp_error, 100 * test::differing_share(vtk, peel, 3), 100 * test::differing_share(sort, peel, 3));
  EXPECT_LE(bsp_error, 0.001) << "at least 99.9% of pixels within 3/255 of the exact reference";
  EXPECT_GT(test::differing_share(vtk, peel, 3), bsp_error) << "unsorted blending should be visibly off";
}

TEST_F(VolumeRender, SceneFilePathsAreRelativeToItAndOptionsOverrideIt) {
  TERRAVOL_REQUIRE_DISPLAY();
  const auto scene = path("relative.json");
  std::ofstream(scene) << R"({"dem": ")" << bundled_dem() << R"(", "volumes": [{"file": "rf1.vdb",
    "isosurfaces": [{"value": 110}]}], "camera": {"lat": 45.44, "lon": 6.44, "alt": 2600, "heading": 40,
    "pitch": -18}, "render": {"size": "320x180"}})";
  const test::Image a = render("--scene " + scene.string(), "scene_a");
  EXPECT_EQ(a.width, 320) << "the file's size";
  const test::Image b = render("--scene " + scene.string() + " --size 200x100", "scene_b");
  EXPECT_EQ(b.width, 200) << "the option wins";
  EXPECT_EQ(b.height, 100);
}

// Two transmitters 8 km apart west and east (`terravol rf --tx A --tx B`), their best_server
// drawn as an opaque categorical slice and seen from straight above, north up: the west half of
// the image holds mostly the first transmitter's colour and the east half the second's (tab20's
// blue and orange, written out here), and a continuous map shows neither.
TEST_F(VolumeRender, BestServerSliceIsDrawnInEachTransmittersColourOnItsSide) {
  TERRAVOL_REQUIRE_DISPLAY();
  const std::string two = path("two.vdb").string();
  const auto r = run_terravol("rf --quiet --tx 45.50,6.50,60,900,50,name=west --tx 45.50,6.60,60,900,50,name=east --dem " +
                                  bundled_dem() + " --radius-km 6 --heights 0:400:100 -o " + two,
                              120);
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string view = " --camera 45.50,6.55,9000,0,-90 --size 300x200 --no-legend --volume " + two +
                           " --field best_server --slice agl=100,opacity=1,colormap=";
  const test::Image by_server = render(bundled_dem() + view + "categorical", "best_server");
  const test::Image viridis = render(bundled_dem() + view + "viridis", "best_server_viridis");
  ASSERT_EQ(by_server.width, 300);
  const test::Rgb8 blue{31, 119, 180}, orange{255, 127, 14};
  auto share = [](const test::Image& img, int x0, int x1, const test::Rgb8& c) {
    std::size_t n = 0, all = 0;
    for (int y = 0; y < img.height; ++y)
      for (int x = x0; x < x1; ++x, ++all) n += test::same_color(img.at(x, y), c, 40);
    return static_cast<double>(n) / static_cast<double>(all);
  };
  const int w = by_server.width, third = w / 3;
  EXPECT_GT(share(by_server, 0, third, blue), 0.4);
  EXPECT_LT(share(by_server, 0, third, orange), 0.1);
  EXPECT_GT(share(by_server, w - third, w, orange), 0.4);
  EXPECT_LT(share(by_server, w - third, w, blue), 0.1);
  EXPECT_LT(share(viridis, 0, w, orange), 0.01);
}

TEST_F(VolumeRender, BadVolumesAndStylesFailWithOneLine) {
  const auto garbage = path("garbage.vdb");
  std::ofstream(garbage) << "not a vdb at all";
  auto one_line = [](const test::CommandResult& r) {
    return r.err.find('\n') == r.err.size() - 1;
  };
  auto r = run_terravol("render " + bundled_dem() + kView + " --volume " + garbage.string() + " -o " +
                        path("x.png").string());
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find(garbage.string()), std::string::npos) << r.err;
  EXPECT_TRUE(one_line(r)) << r.err;
  r = run_terravol("render " + bundled_dem() + kView + " --volume " + volume(0) + " --slice lat=47 -o " +
                   path("x.png").string());
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("rf0.vdb"), std::string::npos) << r.err;
  EXPECT_TRUE(one_line(r)) << r.err;
  r = run_terravol("render " + bundled_dem() + kView + " --volume " + volume(0) + " --iso 100,opacity=7 -o " +
                   path("x.png").string());
  EXPECT_EQ(r.status, 1);
  EXPECT_TRUE(one_line(r)) << r.err;
  r = run_terravol("render " + bundled_dem() + kView + " --order painter -o " + path("x.png").string());
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("--order painter"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(path("x.png")));
}

}  // namespace
}  // namespace terravol
