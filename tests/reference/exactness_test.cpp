// The independent image test of issue 11: `terravol render` of translucent RF isosurfaces and
// slices over the bundled DEM, against the reference built without the tree (reference/check.h),
// from cameras inside a volume, beside one, near the ground, far above, at the window's edges and
// outside, and with objects (a translucent plate through isosurfaces, a tilted mast). Each view must have at least 99.9% of its pixels within 8/255 of the reference.
//
// The executable under test is TERRAVOL_UNDER_TEST when set (e.g. another checkout's build),
// else this build's terravol. The volumes are made by this build's `terravol rf` at small sizes
// (6" spacing, 0-1000 m every 100 m) so that the test stays quick; the render style is the
// issue's: --full-res --surface-triangles 0 --haze 0, a uniform background (the sky gradient in
// one view), no legend, a 256-cell window so that volumes straddle its edges. When a view fails, its three images (ours,
// the reference, the difference) are kept in reference-failures/ of the working directory.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "objects/test_models.h"
#include "reference/check.h"
#include "run_command.h"
#include "temp_dir.h"

namespace terravol::reference {
namespace {

namespace fs = std::filesystem;

constexpr double kTarget = 0.999;  // issue 11: >= 99.9% of pixels within 8/255, every view

struct View {
  const char* name;
  const char* scene;   // "volumes" or "terrain"
  const char* camera;  // LAT,LON,ALT,HEADING,PITCH, ALT above the ground
  bool sky = false;    // the renderer's sky gradient rather than a uniform background
};

const View kViews[] = {
    {"inside_volume", "volumes", "45.505,6.49,250,60,-10"},
    {"beside_volume", "volumes", "45.50,6.455,400,0,-8"},
    {"near_ground", "volumes", "45.51,6.52,12,200,2"},
    {"far_above", "volumes", "45.50,6.50,9000,0,-75"},
    {"outside", "volumes", "45.40,6.40,2500,35,-20", true},
    {"window_edge_south", "volumes", "45.004,6.05,200,10,-5"},
    {"window_edge_east", "volumes", "45.49,6.44,300,90,-10"},
    // The reference's own floor: the terrain alone, where only the colours' sampling differs
    // (vertex colours here, the renderer's bilinear texture there).
    {"terrain_only", "terrain", "45.45,6.45,1500,30,-20"},
    // Objects (issue 16): a translucent plate standing through the isosurfaces of the first
    // volume and a turned, tilted opaque mast, from inside the volume and from above.
    {"objects_inside_volume", "objects", "45.4995,6.487,120,75,-4"},
    {"objects_from_above", "objects", "45.492,6.492,900,30,-40"},
    // Real models (assimp-testmodels): the glTF milk truck (node transforms, base colours) and
    // Wuson (PLY) translucent, crossing an isosurface.
    {"real_models", "models", "45.4990,6.4960,60,50,-10"},
};

constexpr const char* kTruck = "glTF/CesiumMilkTruck/CesiumMilkTruck.gltf";
constexpr const char* kWuson = "PLY/Wuson.ply";

// The name alone in test listings (gtest would print the struct's bytes).
void PrintTo(const View& v, std::ostream* os) { *os << v.name; }

fs::path under_test() {
  const char* env = std::getenv("TERRAVOL_UNDER_TEST");
  return env != nullptr && *env ? fs::path(env) : fs::path(TERRAVOL_EXE);
}

class Exactness : public ::testing::TestWithParam<View> {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::make_unique<test::TempDir>();
    const fs::path dem = fs::path(TERRAVOL_SOURCE_DIR) / "data" / "dem" / "N45E006.hgt";
    // Three volumes: two overlapping near the tile's centre, one at its south edge.
    const char* volumes[][3] = {{"a.vdb", "45.50,6.50,30", "3"}, {"b.vdb", "45.52,6.54,20", "2.5"},
                                {"c.vdb", "45.02,6.05,30", "3"}};
    for (const auto& v : volumes) {
      const auto r = test::run_terravol("rf --quiet --tx " + std::string(v[1]) + " --radius-km " + v[2] +
                                        " --spacing 6 --heights 0:1000:100 --dem " + dem.string() + " -o " +
                                        (dir_->path() / v[0]).string(), 120);
      ASSERT_EQ(r.status, 0) << r.err;
    }
    std::ofstream(dir_->path() / "volumes.json") << R"({"dem": [")" << dem.string() << R"("],
 "volumes": [
  {"file": "a.vdb",
   "isosurfaces": [{"value": 95, "color": [230, 159, 0], "opacity": 0.5},
                   {"value": 110, "color": [86, 180, 233], "opacity": 0.35}],
   "slices": [{"agl": 300, "colormap": "viridis", "opacity": 0.5, "range": [70, 140]}]},
  {"file": "b.vdb",
   "isosurfaces": [{"value": 100, "color": [0, 158, 115], "opacity": 0.45},
                   {"value": 115, "color": [213, 94, 0], "opacity": 0.3}],
   "slices": [{"lat": 45.52, "colormap": "plasma", "opacity": 0.4}]},
  {"file": "c.vdb",
   "isosurfaces": [{"value": 100, "color": [204, 121, 167], "opacity": 0.5}],
   "slices": [{"lon": 6.04, "colormap": "turbo", "opacity": 0.5, "range": [70, 150]}]}],
 "render": {"size": "640x360", "window": 256, "legend": false}}
)";
    std::ofstream(dir_->path() / "terrain.json") << R"({"dem": [")" << dem.string() << R"("],
 "render": {"size": "640x360", "window": 256, "legend": false}}
)";
    // Two models written here (OBJ with materials, read by assimp on both sides): a unit plate
    // in the model's x-y plane (+Y up, so it stands facing its front) and a 20 x 20 x 200 box
    // (+Z up).
    std::ofstream(dir_->path() / "models.mtl") << "newmtl red\nKd 0.9 0.25 0.1\nd 1.0\n"
                                                  "newmtl blue\nKd 0.2 0.3 0.9\nd 1.0\n";
    std::ofstream(dir_->path() / "plate.obj") << "mtllib models.mtl\nusemtl red\n"
                                                 "v -1 0 0\nv 1 0 0\nv 1 1 0\nv -1 1 0\nf 1 2 3 4\n";
    std::ofstream(dir_->path() / "mast.obj") << "mtllib models.mtl\nusemtl blue\n"
                                                "v -10 -10 0\nv 10 -10 0\nv 10 10 0\nv -10 10 0\n"
                                                "v -10 -10 200\nv 10 -10 200\nv 10 10 200\nv -10 10 200\n"
                                                "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";
    std::ofstream(dir_->path() / "objects.json") << R"({"dem": [")" << dem.string() << R"("],
 "volumes": [
  {"file": "a.vdb",
   "isosurfaces": [{"value": 95, "color": [230, 159, 0], "opacity": 0.5},
                   {"value": 110, "color": [86, 180, 233], "opacity": 0.35}]}],
 "objects": [
  {"file": "plate.obj", "lat": 45.5005, "lon": 6.4975, "agl": 0, "heading": 30, "scale": 700, "opacity": 0.5},
  {"file": "mast.obj", "lat": 45.4985, "lon": 6.4965, "agl": 0, "heading": 70, "pitch": 15, "roll": 10, "up": "z"}],
 "render": {"size": "640x360", "window": 256, "legend": false}}
)";
    std::ofstream(dir_->path() / "models.json") << R"({"dem": [")" << dem.string() << R"("],
 "volumes": [{"file": "a.vdb", "isosurfaces": [{"value": 95, "color": [230, 159, 0], "opacity": 0.5}]}],
 "objects": [
  {"file": ")" << test::assimp_model(kTruck).string() << R"(", "lat": 45.5005, "lon": 6.4975, "heading": 45, "scale": 20},
  {"file": ")" << test::assimp_model(kWuson).string() << R"(", "lat": 45.5002, "lon": 6.4990, "heading": 200, "scale": 40, "opacity": 0.6}],
 "render": {"size": "640x360", "window": 256, "legend": false}}
)";
  }
  static void TearDownTestSuite() { dir_.reset(); }
  static std::unique_ptr<test::TempDir> dir_;
};

std::unique_ptr<test::TempDir> Exactness::dir_;

TEST_P(Exactness, WithinEightLevelsOfTheReference) {
  try {
    require_display();
  } catch (const std::runtime_error& e) {
    GTEST_SKIP() << e.what();
  }
  const View& v = GetParam();
  if (std::string(v.scene) == "models") {
    REQUIRE_ASSIMP_MODEL(kTruck);
    REQUIRE_ASSIMP_MODEL(kWuson);
  }
  const fs::path scene = dir_->path() / (std::string(v.scene) + ".json");
  std::vector<std::string> args{"--camera", v.camera, "--agl", "--fov", "50"};
  if (!v.sky) args.insert(args.end(), {"--background", "205,222,240"});
  const RenderRun run = run_render(under_test(), scene, dir_->path(), v.name, args, 300);
  const Reference ref = reference_image(scene, run.vtp, run.stats);
  const Image ours = read_png(run.png);
  const double within8 = share_within(ref.image, ours, 8), within3 = share_within(ref.image, ours, 3);
  std::printf("%s: %.4f%% of pixels within 8/255, %.4f%% within 3/255 (terrain %zu, merged %zu drawn; "
              "reference %zu volume and %zu object triangles)\n",
              v.name, 100 * within8, 100 * within3, ref.drawn.terrain_triangles, ref.drawn.merged_triangles,
              ref.volume_triangles, ref.object_triangles);
  if (within8 < kTarget) {
    const fs::path keep = fs::current_path() / "reference-failures";
    fs::create_directories(keep);
    write_png(keep / (std::string(v.name) + "-ours.png"), ours);
    write_png(keep / (std::string(v.name) + "-reference.png"), ref.image);
    write_png(keep / (std::string(v.name) + "-difference.png"), difference_image(ref.image, ours, 8));
    std::printf("kept the images in %s\n", keep.c_str());
  }
  EXPECT_GE(within8, kTarget) << v.name << ": " << 100 * (1 - within8) << "% of pixels differ by more than 8/255";
  if (std::string(v.scene) != "terrain") {
    EXPECT_GT(ref.volume_triangles, 0u);
  }
  if (std::string(v.scene) == "objects") {
    EXPECT_EQ(ref.object_triangles, 2u + 12u);
  }
  if (std::string(v.scene) == "models") {
    EXPECT_GT(ref.object_triangles, 7000u);  // the truck's 3,624 and Wuson's 3,732
  }
}

INSTANTIATE_TEST_SUITE_P(Views, Exactness, ::testing::ValuesIn(kViews),
                         [](const ::testing::TestParamInfo<View>& p) { return std::string(p.param.name); });

}  // namespace
}  // namespace terravol::reference
