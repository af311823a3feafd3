// `terravol bench` as a user runs it: a small run on the bundled DEM writes its JSON, report and
// plots; bad options fail with one line.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fstream>

#include "require_display.h"
#include "run_command.h"

namespace terravol {
namespace {

using test::run_terravol;

TEST(BenchCli, UnknownSuiteOrMissingDemFailsWithOneLine) {
  test::TempDir dir;
  auto r = run_terravol("bench --suites terrain,fast -o " + dir.path().string());
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("unknown suite 'fast'"), std::string::npos) << r.err;
  r = run_terravol("bench --suites build --dem /nonexistent/N00E000.hgt -o " + dir.path().string());
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("/nonexistent/N00E000.hgt: no such file"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "report.md"));
}

TEST(BenchCli, ExactnessNeedsItsSceneAndAnExistingExecutableUnderTest) {
  test::TempDir dir;
  const std::string dem = std::string(TERRAVOL_SOURCE_DIR) + "/data/dem/N45E006.hgt";
  auto r = run_terravol("bench --suites exactness --under-test /nonexistent/terravol --dem " + dem + " -o " +
                        dir.path().string());
  EXPECT_NE(r.status, 0);  // CLI11's validation error
  EXPECT_NE(r.err.find("/nonexistent/terravol"), std::string::npos) << r.err;
  // A terrain without the scene is skipped with a message, not drawn.
  r = run_terravol("bench --suites exactness --dem " + dem + " -o " + dir.path().string(), 120);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("exactness: no scene for N45E006"), std::string::npos) << r.err;
  std::ifstream in(dir.path() / "results.json");
  EXPECT_FALSE(nlohmann::json::parse(in).contains("exactness"));
}

TEST(BenchCli, ASmallRunOnTheBundledDemWritesResultsReportAndPlots) {
  TERRAVOL_REQUIRE_DISPLAY();
  test::TempDir dir;
  const std::string dem = std::string(TERRAVOL_SOURCE_DIR) + "/data/dem/N45E006.hgt";
  const auto r = run_terravol("bench --suites build,terrain --views 2 --repeats 1 --dem " + dem + " -o " +
                                  dir.path().string(),
                              300);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("full-res VTK / MRBSP at 1 px, N45E006: "), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("terrain N45E006: view 2/2"), std::string::npos) << "progress on stderr: " << r.err;

  std::ifstream in(dir.path() / "results.json");
  const auto j = nlohmann::json::parse(in);
  const auto& t = j["terrain"][0];
  EXPECT_EQ(t["views"], 2);
  EXPECT_EQ(t["mrbsp"].size(), 10u) << "4 thresholds x 2 metrics, and 1 and 2 px with occlusion culling";
  // Plain VTK draws every triangle of the 1024-cell window; the MRBSP at 1 px far fewer.
  EXPECT_EQ(t["plain_vtk"]["triangles"].get<double>(), 2.0 * 1024 * 1024);
  for (const auto& k : t["mrbsp"]) {
    EXPECT_LT(k["triangles"]["median"].get<double>(), 2.0 * 1024 * 1024);
    EXPECT_GT(k["psnr_db"]["median"].get<double>(), 20.0);
    EXPECT_GT(k["ssim"]["median"].get<double>(), 0.5);
  }
  // Occlusion culling leaves the image as it is and draws no more triangles.
  for (std::size_t k : {std::size_t{8}, std::size_t{9}}) {
    const auto& on = t["mrbsp"][k];
    EXPECT_TRUE(on["occlusion"].get<bool>());
    EXPECT_EQ(on["images_identical_to_off"].get<double>(), 1.0);
    EXPECT_LE(on["triangles"]["median"].get<double>(), t["mrbsp"][k - 7]["triangles"]["median"].get<double>());
  }
  // Coarser thresholds draw fewer triangles.
  EXPECT_GT(t["mrbsp"][0]["triangles"]["median"].get<double>(), t["mrbsp"][3]["triangles"]["median"].get<double>());
  const auto& b = j["build"][0];
  EXPECT_GT(b["build_over_slide"].get<double>(), 0.0) << "reported (its size is a bench figure, not a test: it varies with load)";
  EXPECT_GT(b["bytes_per_sample"]["total"].get<double>(), 0.0);
  // The bundled tile is barely wider than the window: the viewer's flight east lands no slide,
  // and says so.
  EXPECT_EQ(b["viewer_slides"]["slides"].get<std::size_t>(), 0u);
  EXPECT_FALSE(b["viewer_slides"].contains("landing_frame_ms"));

  std::ifstream md(dir.path() / "report.md");
  const std::string report((std::istreambuf_iterator<char>(md)), std::istreambuf_iterator<char>());
  EXPECT_NE(report.find("## 1. Terrain flythrough"), std::string::npos);
  EXPECT_NE(report.find("## 4. Build and slide"), std::string::npos);
  EXPECT_NE(report.find("| N45E006 | 0 | no slide"), std::string::npos) << "the viewer's slides' row";
  for (const char* plot : {"plot-frame-time-N45E006.png", "plot-triangles-threshold.png", "plot-error-threshold.png"}) {
    EXPECT_TRUE(std::filesystem::exists(dir.path() / plot)) << plot;
    EXPECT_NE(report.find(plot), std::string::npos) << plot;
  }
}

// The low-altitude suite's code path on a tiny case (one low view, one repetition, a 4-frame
// flight): what it checks must hold however small the run. Its figures are not tested here.
TEST(BenchCli, LowAltitudeSuiteCullsOnlyHiddenTrianglesAndKeepsImagesIdentical) {
  TERRAVOL_REQUIRE_DISPLAY();
  test::TempDir dir;
  const std::string dem = std::string(TERRAVOL_SOURCE_DIR) + "/data/dem/N45E006.hgt";
  const auto r = run_terravol("bench --suites lowalt --quick --views 1 --repeats 1 --frames 4 --dem " + dem + " -o " +
                                  dir.path().string(),
                              300);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("low altitude N45E006 at 1 px: occlusion off / on "), std::string::npos) << r.out;
  std::ifstream in(dir.path() / "results.json");
  const auto j = nlohmann::json::parse(in);
  const auto& t = j["lowalt"][0];
  EXPECT_EQ(t["low_views"], 1);
  ASSERT_EQ(t["occlusion"].size(), 4u) << "low and high views, 1 and 2 px";
  for (const auto& k : t["occlusion"]) {
    EXPECT_EQ(k["images_identical"].get<double>(), 1.0);
    EXPECT_EQ(k["visible_culled"].get<double>(), 0.0) << "a culled triangle showed in the item buffer";
    EXPECT_EQ(k["triangles_on_not_off"].get<double>(), 0.0);
    EXPECT_LE(k["on"]["triangles"]["median"].get<double>(), k["off"]["triangles"]["median"].get<double>());
    EXPECT_LE(k["hidden_culled_share"]["median"].get<double>(), 1.0);
    EXPECT_LT(k["crack_pixel_share"]["median"].get<double>(), 1.0);
  }
  const auto& f = t["flight"];
  EXPECT_EQ(f["frames"], 4);
  // (Hierarchy updating may query more than testing every node in a frame where an opened
  // node became hidden: its children are queried instead of it. Only the images are invariant.)
  for (const char* mode : {"every_node", "update", "conservative"}) {
    EXPECT_EQ(f[mode]["images_identical"].get<double>(), 1.0) << mode;
    EXPECT_GT(f[mode]["tests_over_every_node"].get<double>(), 0.0) << mode;
  }
  EXPECT_EQ(f["every_node"]["tests_over_every_node"].get<double>(), 1.0);
  std::ifstream md(dir.path() / "report.md");
  const std::string report((std::istreambuf_iterator<char>(md)), std::istreambuf_iterator<char>());
  EXPECT_NE(report.find("## 10. Low altitude"), std::string::npos);
}

}  // namespace
}  // namespace terravol
