// `terravol render` as a user runs it: images of the bundled and the real DEMs, the tree's
// order against the depth-buffer reference, cracks, the exports, and bad arguments.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <vtkCellArray.h>
#include <vtkDataArray.h>
#include <vtkFieldData.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkXMLPolyDataReader.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <string>

#include "image_compare.h"
#include "require_display.h"
#include "run_command.h"
#include "shared_data.h"
#include "temp_dir.h"

namespace terravol {
namespace {

using test::run_terravol;

const test::Rgb8 kMagenta{255, 0, 255};

std::string bundled_dem() { return std::string(TERRAVOL_SOURCE_DIR) + "/data/dem/N45E006.hgt"; }

std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

TEST(RenderCli, BundledDemGivesAnImageOfTheRequestedSizeThatIsNotAllBackground) {
  TERRAVOL_REQUIRE_DISPLAY();
  test::TempDir dir;
  const auto png = dir.path() / "view.png";
  const auto r = run_terravol("render " + bundled_dem() + " --camera 45.1,6.3,4500,35,-20 --size 400x300 -o " +
                              png.string() + " --background 255,0,255");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("wrote " + png.string()), std::string::npos) << r.out;
  const auto img = test::read_png(png);
  ASSERT_EQ(img.width, 400);
  ASSERT_EQ(img.height, 300);
  const double sky = test::color_share(img, kMagenta, 0);
  EXPECT_GT(sky, 0.02) << "the view should show some sky above the terrain";
  EXPECT_LT(sky, 0.7) << "the terrain should fill much of the image";
}

TEST(RenderCli, DefaultSkyViewOfTheBundledDemIsWritten) {
  TERRAVOL_REQUIRE_DISPLAY();
  test::TempDir dir;
  const auto png = dir.path() / "default.png";
  const auto r = run_terravol("render " + bundled_dem() + " --camera 45.02,6.1,7000,40,-22 -o " + png.string());
  ASSERT_EQ(r.status, 0) << r.err;
  const auto img = test::read_png(png);
  EXPECT_EQ(img.width, 1280);
  EXPECT_EQ(img.height, 720);
  // Not one flat colour: terrain and sky.
  EXPECT_LT(test::color_share(img, img.at(img.width / 2, img.height - 1), 2), 0.5);
  EXPECT_LT(test::color_share(img, img.at(img.width / 2, 0), 2), 0.5);
}

// Renders `view` (everything of the command line but the output) with --order bsp and with
// --order zbuffer (VTK's depth-tested draw of the very same triangles) into `dir`; expects at
// most 0.5% of pixels to differ (silhouettes) and returns the bsp image.
test::Image expect_bsp_matches_zbuffer(const test::TempDir& dir, const std::string& view) {
  const auto bsp = dir.path() / "bsp.png", zbuffer = dir.path() / "zbuffer.png";
  auto r = run_terravol("render " + view + " -o " + bsp.string() + " --order bsp");
  EXPECT_EQ(r.status, 0) << r.err;
  r = run_terravol("render " + view + " -o " + zbuffer.string() + " --order zbuffer");
  EXPECT_EQ(r.status, 0) << r.err;
  const auto a = test::read_png(bsp), b = test::read_png(zbuffer);
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
  if (a.width != b.width || a.height != b.height) return a;
  const double share = test::differing_share(a, b, 8);
  EXPECT_LE(share, 0.005) << share * 100 << "% of pixels differ";
  return a;
}

// The tree's back-to-front order with no depth test against VTK's depth-tested draw of the
// very same triangles (opaque terrain): only silhouette pixels may differ.
TEST(RenderCli, BspOrderMatchesTheDepthBufferReference) {
  TERRAVOL_REQUIRE_DISPLAY();
  const auto dem = test::shared_dem("N44W072.hgt");
  TERRAVOL_REQUIRE_SHARED(dem);
  test::TempDir dir;
  expect_bsp_matches_zbuffer(dir, dem.string() + " --camera 44.12,-71.5,2200,40,-5 --size 960x540");
}

// A camera beyond the DEM (south of the bundled tile, low, looking north) sees the window's
// terrain closed by the wall of its south side: in every column, the pixels between the
// topmost and the bottommost that are not background are none of them background (the
// window's solid projects to one interval per column; a hole would be the terrain's open
// underside), and the wall's earth colour fills a good part of the image.
TEST(RenderCli, CameraBeyondTheDemSeesTheTileClosedByAWall) {
  TERRAVOL_REQUIRE_DISPLAY();
  test::TempDir dir;
  const auto png = dir.path() / "beyond.png";
  const auto r = run_terravol("render " + bundled_dem() + " --agl --camera 44.96,6.5,800,10,-8 --size 480x270 --haze 0 " +
                              "--background 255,0,255 -o " + png.string());
  ASSERT_EQ(r.status, 0) << r.err;
  const auto img = test::read_png(png);
  std::size_t holes = 0, solid = 0;
  for (int x = 0; x < img.width; ++x) {
    int top = -1, bottom = -1;
    for (int y = 0; y < img.height; ++y) {
      if (test::same_color(img.at(x, y), kMagenta, 0)) continue;
      if (top < 0) top = y;
      bottom = y;
    }
    for (int y = top; y >= 0 && y <= bottom; ++y) holes += test::same_color(img.at(x, y), kMagenta, 0) ? 1 : 0;
    solid += top >= 0 ? static_cast<std::size_t>(bottom - top + 1) : 0;
  }
  EXPECT_EQ(holes, 0u);
  EXPECT_GT(solid, static_cast<std::size_t>(img.width) * img.height / 4) << "the tile fills much of the view";
  EXPECT_GT(test::color_share(img, test::Rgb8{112, 96, 78}, 40), 0.15) << "the south wall is seen";
}

// From beyond the DEM too, the tree's order (walls included) against VTK's depth-tested draw
// of the very same triangles: only silhouette pixels may differ.
TEST(RenderCli, BspOrderFromBeyondTheDemMatchesTheDepthBufferReference) {
  TERRAVOL_REQUIRE_DISPLAY();
  test::TempDir dir;
  const auto a = expect_bsp_matches_zbuffer(dir, bundled_dem() + " --agl --camera 44.93,5.95,900,40,-6 --size 480x270");
  EXPECT_GT(test::color_share(a, test::Rgb8{112, 96, 78}, 60), 0.02) << "two walls are seen";
}

// No cracks: with each level in its own colour and a background the terrain never takes, no
// background pixel appears below the terrain's horizon line, from low oblique views.
struct CrackView {
  const char* name;
  const char* dem;     // under ../shared/data/dem
  const char* camera;  // LAT,LON,AGL,HEADING,PITCH
};

void PrintTo(const CrackView& v, std::ostream* os) { *os << v.name; }

class RenderCracks : public ::testing::TestWithParam<CrackView> {};

TEST_P(RenderCracks, NoBackgroundBelowTheTerrainsHorizon) {
  TERRAVOL_REQUIRE_DISPLAY();
  const CrackView v = GetParam();
  const auto dem = test::shared_dem(v.dem);
  TERRAVOL_REQUIRE_SHARED(dem);
  test::TempDir dir;
  const auto png = dir.path() / "cracks.png";
  const auto r = run_terravol("render " + dem.string() + " --agl --camera " + v.camera +
                              " --size 960x540 --lod-colors --background 255,0,255 -o " + png.string());
  ASSERT_EQ(r.status, 0) << r.err;
  const auto img = test::read_png(png);
  ASSERT_EQ(img.width, 960);
  std::array<int, 2> first{-1, -1};
  const std::size_t holes = test::background_below_horizon(img, kMagenta, 0, &first);
  EXPECT_EQ(holes, 0u) << "first background pixel below the horizon at x=" << first[0] << " y=" << first[1];
  EXPECT_LT(test::color_share(img, kMagenta, 0), 0.9) << "the view shows terrain";
}

INSTANTIATE_TEST_SUITE_P(
    LowObliqueViews, RenderCracks,
    ::testing::Values(CrackView{"WhiteMountainsNortheast", "N44W072.hgt", "44.12,-71.5,300,40,-4"},
                      CrackView{"WhiteMountainsWest", "N44W072.hgt", "44.3,-71.25,250,250,-3"},
                      CrackView{"WhiteMountainsSouthFromNorth", "N44W072.hgt", "44.75,-71.6,400,170,-6"},
                      CrackView{"WasatchFromTheValley", "utah_sdf", "40.65,-111.95,300,90,-3"},
                      CrackView{"UintasFromTheWest", "utah_sdf", "40.7,-111.1,500,80,-4"}),
    [](const auto& param_info) { return std::string(param_info.param.name); });

TEST(RenderCli, ExportVtpHoldsTheDrawnTrianglesAndTheCamera) {
  TERRAVOL_REQUIRE_DISPLAY();
  test::TempDir dir;
  const auto png = dir.path() / "v.png", stats = dir.path() / "stats.json", vtp = dir.path() / "drawn.vtp";
  const auto r = run_terravol("render " + bundled_dem() + " --camera 45.2,6.6,3000,300,-15 --size 320x240 --fov 50 -o " +
                              png.string() + " --stats " + stats.string() + " --export-vtp " + vtp.string());
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(slurp(stats));
  for (const char* key : {"triangles", "nodes_visited", "lod_histogram", "traversal_ms", "draw_ms", "build_ms",
                          "window", "levels"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  EXPECT_EQ(j["window"]["cells"], 1024);
  EXPECT_EQ(j["levels"], 8);
  EXPECT_NEAR(j["camera"]["near"].get<double>(), 0.05 * (j["camera"]["eye_height"].get<double>() -
                                                          j["camera"]["ground_height"].get<double>()), 1e-6)
      << "a twentieth of the eye's height by default";
  std::size_t leaves = 0;
  for (const auto& n : j["lod_histogram"]) leaves += n.get<std::size_t>();
  EXPECT_EQ(leaves, j["leaves"].get<std::size_t>());

  vtkNew<vtkXMLPolyDataReader> reader;
  reader->SetFileName(vtp.c_str());
  reader->Update();
  vtkPolyData* poly = reader->GetOutput();
  EXPECT_EQ(poly->GetNumberOfPolys(), j["triangles"].get<vtkIdType>());
  EXPECT_GT(poly->GetNumberOfPolys(), 0);
  EXPECT_LE(poly->GetNumberOfPoints(), j["vertices"].get<vtkIdType>());
  vtkDataArray* rgba = poly->GetPointData()->GetArray("rgba");
  ASSERT_NE(rgba, nullptr);
  EXPECT_EQ(rgba->GetNumberOfComponents(), 4);
  // Normals made at export from the lattice's points: unit, and up on terrain.
  vtkDataArray* normals = poly->GetPointData()->GetNormals();
  ASSERT_NE(normals, nullptr);
  ASSERT_EQ(normals->GetNumberOfTuples(), poly->GetNumberOfPoints());
  for (vtkIdType v = 0; v < normals->GetNumberOfTuples(); ++v) {
    const double* n = normals->GetTuple3(v);
    ASSERT_NEAR(n[0] * n[0] + n[1] * n[1] + n[2] * n[2], 1.0, 1e-5) << v;
    ASSERT_GT(n[2], 0.0) << v;
  }
  vtkFieldData* fd = poly->GetFieldData();
  for (const char* name : {"camera_position", "camera_focal_point", "camera_view_up", "camera_view_angle", "background"}) {
    EXPECT_NE(fd->GetArray(name), nullptr) << name;
  }
  ASSERT_NE(fd->GetArray("camera_view_angle"), nullptr);
  EXPECT_DOUBLE_EQ(fd->GetArray("camera_view_angle")->GetTuple1(0), 50.0);
  ASSERT_NE(fd->GetArray("camera_position"), nullptr);
  EXPECT_NEAR(fd->GetArray("camera_position")->GetComponent(0, 2), j["camera"]["eye"][2].get<double>(), 1e-6);
}

// The tree's order has no depth buffer: a near plane that clips nothing drawn leaves its
// picture unchanged, to the byte.
TEST(RenderCli, NearPlaneIsTheOneGivenAndLeavesTheTreesPictureAloneWhenNothingIsNearer) {
  TERRAVOL_REQUIRE_DISPLAY();
  test::TempDir dir;
  const std::string view = "render " + bundled_dem() + " --camera 45.2,6.6,3000,300,-15 --agl --size 160x120 --force";
  const auto a = dir.path() / "a.png", b = dir.path() / "b.png", stats = dir.path() / "s.json";
  ASSERT_EQ(run_terravol(view + " -o " + a.string()).status, 0);
  const auto r = run_terravol(view + " --near-plane 500 -o " + b.string() + " --stats " + stats.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_DOUBLE_EQ(nlohmann::json::parse(slurp(stats))["camera"]["near"].get<double>(), 500.0);
  EXPECT_EQ(test::read_png(a).pixels, test::read_png(b).pixels);
}

TEST(RenderCli, ExistingOutputIsKeptWithoutForce) {
  TERRAVOL_REQUIRE_DISPLAY();
  test::TempDir dir;
  const auto png = dir.path() / "keep.png";
  std::ofstream(png) << "precious";
  const std::string args = "render " + bundled_dem() + " --camera 45.5,6.5,4000,0,-20 --size 64x48 -o " + png.string();
  const auto r = run_terravol(args);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("--force"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(png), "precious");
  const auto forced = run_terravol(args + " --force");
  ASSERT_EQ(forced.status, 0) << forced.err;
  EXPECT_EQ(test::read_png(png).width, 64);
  // No temporary file is left beside the output.
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), std::filesystem::directory_iterator()), 1);
}

// Bad arguments: one line "terravol: ...", exit status 1 or 2, quickly, and no output file.
void expect_clean_failure(const std::string& args, const std::string& must_mention) {
  test::TempDir dir;
  const auto png = dir.path() / "never.png";
  const auto r = run_terravol("render " + args + " -o " + png.string());
  EXPECT_TRUE(r.status == 1 || r.status == 2) << args << " exited " << r.status << "\n" << r.err;
  EXPECT_LT(r.seconds, 5.0) << args;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_EQ(r.err.rfind("terravol: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find(must_mention), std::string::npos) << args << ": " << r.err;
  EXPECT_FALSE(std::filesystem::exists(png)) << args;
}

TEST(RenderCli, BadArgumentsFailCleanlyWithOneLine) {
  const std::string dem = bundled_dem();
  expect_clean_failure(dem + " --camera 45.5,6.5,3000", "--camera");
  expect_clean_failure(dem + " --camera 45.5,6.5,3000,0,-10 --near-plane abc", "--near-plane");  // CLI11's own check
  expect_clean_failure(dem + " --camera 45.5,6.5,3000,0,-10 --no-such-option", "--no-such-option");
  expect_clean_failure(dem + " --camera 45.5,6.5,3000,north,-10", "--camera");
  expect_clean_failure(dem + " --camera 45.5,6.5,3000,0,-100", "pitch");
  expect_clean_failure(dem + " --camera 45.5,6.5,3000,0,-10 --size 0x0", "--size");
  expect_clean_failure(dem + " --camera 45.5,6.5,3000,0,-10 --size 1280", "--size");
  expect_clean_failure(dem + " --camera 48.5,6.5,3000,0,-10", "278.0 km beyond the DEM");
  expect_clean_failure(dem + " --camera 45.5,10.5,3000,0,-10", "km beyond the DEM");
  expect_clean_failure(dem + " --camera 45.5,6.5,3000,0,-10 --lod-metric pixels", "--lod-metric");
  expect_clean_failure(dem + " --camera 45.5,6.5,3000,0,-10 --order painter", "--order");
  expect_clean_failure(dem + " --camera 45.5,6.5,3000,0,-10 --window 1000", "--window");
  expect_clean_failure(dem + " --camera 45.5,6.5,3000,0,-10 --background 1,2", "--background");
  expect_clean_failure(dem + " --camera 45.5,6.5,3000,0,-10 --threshold 0", "--threshold");
  expect_clean_failure(dem + " --camera 45.5,6.5,3000,0,-10 --fov 180", "--fov");
  expect_clean_failure(dem + " --camera 45.5,6.5,3000,0,-10 --near-plane -1", "--near-plane");
  expect_clean_failure(dem + " --camera 45.5,6.5,3000,0,-10 --near-plane 1e9", "--near-plane");
  expect_clean_failure(dem + " --camera 45.5,6.5,3000,0,-10 --tint purple", "--tint");
  expect_clean_failure(std::string(TERRAVOL_SOURCE_DIR) + "/missing.hgt --camera 45.5,6.5,3000,0,-10", "missing.hgt");
  // Options for volumes with no volume: refused, not a picture without them.
  expect_clean_failure(dem + " --camera 45.5,6.5,3000,0,-10 --iso 110", "--iso needs a volume");
  expect_clean_failure(dem + " --camera 45.5,6.5,3000,0,-10 --slice agl=300", "--slice needs a volume");
  expect_clean_failure(dem + " --camera 45.5,6.5,3000,0,-10 --volume-frame geographic", "--volume-frame needs a volume");
}

TEST(RenderCli, AnOutputNotNamedPngIsRefusedBeforeAnythingIsWritten) {
  test::TempDir dir;
  for (const char* name : {"view.jpg", "view", "view.png.txt"}) {
    const auto out = dir.path() / name;
    const auto r = run_terravol("render " + bundled_dem() + " --camera 45.5,6.5,3000,0,-10 -o " + out.string());
    EXPECT_EQ(r.status, 1) << name << "\n" << r.err;
    EXPECT_EQ(r.err, "terravol: -o " + out.string() + ": expected a .png file name\n");
    EXPECT_FALSE(std::filesystem::exists(out)) << name;
  }
}

TEST(RenderCli, BadObjectsFailCleanlyWithOneLine) {
  TERRAVOL_REQUIRE_DISPLAY();
  const std::string view = bundled_dem() + " --camera 45.5,6.5,3000,0,-10 --object ";
  expect_clean_failure(view + "truck.glb", "--object 'truck.glb': expected FILE@LAT,LON,AGL");
  expect_clean_failure(view + "truck.glb@45.5,6.5,0,scale=0", "scale");
  expect_clean_failure(view + std::string(TERRAVOL_SOURCE_DIR) + "/missing.glb@45.5,6.5,0", "missing.glb: no such file");
  // A file that is no model: the DEM itself.
  expect_clean_failure(view + bundled_dem() + "@45.5,6.5,0", bundled_dem() + ": ");
  // A real model off the DEM, and one absurdly large.
  test::TempDir dir;
  const auto box = dir.path() / "box.obj";
  std::ofstream(box) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  expect_clean_failure(view + box.string() + "@47.5,6.5,0", box.string() + ": placed at 47.50000, 6.50000, outside the DEM");
  expect_clean_failure(view + box.string() + "@45.5,6.5,0,scale=100000", box.string() + ": 141 km across at scale 100000");
}

TEST(RenderCli, CameraBelowTheGroundOrBadLevelsFailCleanly) {
  TERRAVOL_REQUIRE_DISPLAY();
  const std::string dem = bundled_dem();
  expect_clean_failure(dem + " --camera 45.5,6.5,-50,0,-10", "not above the ground");
  expect_clean_failure(dem + " --agl --camera 45.5,6.5,0,0,-10", "not above the ground");
  expect_clean_failure(dem + " --camera 45.5,6.5,5000,0,-10 --levels 20", "--levels");
}

// The transmitter a volume records gets a red mast with its name above it (white billboard
// text: "tx" for a single rf volume's); --no-markers leaves both out and nothing else changes.
// The volume has no isosurface or slice, so the mast is all that is merged.
TEST(RenderCli, TheTransmitterAVolumeRecordsGetsALabelledMarkerUnlessNoMarkers) {
  TERRAVOL_REQUIRE_DISPLAY();
  test::TempDir dir;
  const std::string vdb = (dir.path() / "rf.vdb").string();
  const auto rf = test::run_terravol("rf --quiet --tx 45.5,6.5,30 --dem " + bundled_dem() +
                                     " --radius-km 2 --heights 0:200:100 -o " + vdb, 300);
  ASSERT_EQ(rf.status, 0) << rf.err;
  struct Seen {
    std::size_t red = 0, white = 0;
    int red_top = 1 << 30, white_bottom = -1;  // image rows, 0 at the top
  };
  const auto seen = [&](const std::string& extra) {
    const std::string png = (dir.path() / ("m" + std::to_string(extra.size()) + ".png")).string();
    const auto r = test::run_terravol("render " + bundled_dem() + " --volume " + vdb +
                                      " --camera 45.47,6.47,400,45,-8 --agl --size 640x360 -o " + png + extra);
    EXPECT_EQ(r.status, 0) << r.err;
    const test::Image img = test::read_png(png);
    Seen s;
    for (int y = 0; y < img.height; ++y)
      for (int x = 0; x < img.width; ++x) {
        const auto& p = img.at(x, y);
        if (p[0] > 180 && p[1] < 80 && p[2] < 90) {
          ++s.red;
          s.red_top = std::min(s.red_top, y);
        }
        if (p[0] > 245 && p[1] > 245 && p[2] > 245) {
          ++s.white;
          s.white_bottom = std::max(s.white_bottom, y);
        }
      }
    return s;
  };
  const Seen with = seen(""), without = seen(" --no-markers");
  EXPECT_GT(with.red, 20u) << "a mast and its diamond some ten pixels across";
  EXPECT_GT(with.white, 10u) << "the label";
  EXPECT_LE(with.white_bottom, with.red_top + 2) << "the label stands above the marker";
  EXPECT_EQ(without.red, 0u);
  EXPECT_EQ(without.white, 0u);
}

}  // namespace
}  // namespace terravol
