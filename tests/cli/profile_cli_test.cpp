// `terravol profile` through the executable: a ridge DEM worked out by hand, the path loss
// against `terravol rf` at the same lattice points, the plot's pixels, bad input.
#include <GeographicLib/Geodesic.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "cli_test_util.h"
#include "image_compare.h"
#include "require_display.h"
#include "run_command.h"
#include "temp_dir.h"

namespace terravol::app::cli {
namespace {

using test::bundled_dem;
using test::expect_one_line_error;
using test::run_terravol;

// 3" samples over 45.45..45.6166 N, 6.5..6.8333 E, flat at 0 m but for a 60 m north-south ridge
// whose flat top spans 6.55..6.5525 E.
std::filesystem::path write_ridge(const std::filesystem::path& dir) {
  const auto path = dir / "ridge.asc";
  std::ofstream out(path);
  out << "ncols 401\nnrows 201\nxllcenter 6.5\nyllcenter 45.45\ncellsize 0.000833333333333333\n";
  for (int r = 0; r < 201; ++r) {
    for (int c = 0; c < 401; ++c) out << (c >= 60 && c <= 63 ? "60 " : "0 ");
    out << "\n";
  }
  return path;
}

std::vector<std::vector<double>> read_csv(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);  // header
  std::vector<std::vector<double>> rows;
  while (std::getline(in, line)) {
    std::vector<double> row;
    std::stringstream s(line);
    std::string field;
    while (std::getline(s, field, ',')) row.push_back(std::strtod(field.c_str(), nullptr));
    rows.push_back(row);
  }
  return rows;
}

// The number after `key` in `text`.
double after(const std::string& text, const std::string& key) {
  const std::size_t at = text.find(key);
  EXPECT_NE(at, std::string::npos) << key << " in " << text;
  return at == std::string::npos ? NAN : std::strtod(text.c_str() + at + key.size(), nullptr);
}

TEST(ProfileCli, RidgeClearanceAgreesWithTheHandComputedKnifeEdge) {
  TERRAVOL_REQUIRE_DISPLAY();
  test::TempDir dir;
  const auto dem = write_ridge(dir.path());
  const auto png = dir.path() / "p.png", csv = dir.path() / "p.csv";
  const auto r = run_terravol("profile --from 45.5,6.5,30 --to 45.5,6.625,10 --dem " + dem.string() + " -o " +
                              png.string() + " --csv " + csv.string());
  ASSERT_EQ(r.status, 0) << r.err;
  // The worst obstruction, as printed: its distance, clearance and clearance in F1.
  const double d_km = after(r.out, "worst obstruction at ");
  const double clearance = after(r.out, "clearance ");
  const double in_f1 = after(r.out, " m = ");
  // By hand at that distance: the ridge's top is 60 m; the bulge for k = 4/3; the straight line
  // from 30 m to 10 m above the flat ground at 0; F1 at 900 MHz.
  double D = 0.0;
  GeographicLib::Geodesic::WGS84().Inverse(45.5, 6.5, 45.5, 6.625, D);
  const double d = d_km * 1000.0;
  const double bulge = d * (D - d) / (2.0 * 4.0 / 3.0 * 6371000.0);
  const double hand = 30.0 + (10.0 - 30.0) * d / D - (60.0 + bulge);
  const double f1 = std::sqrt(299792458.0 / 900e6 * d * (D - d) / D);
  EXPECT_NEAR(clearance, hand, 0.1);   // the target
  EXPECT_NEAR(clearance, hand, 0.01);  // printed to 0.01 m; d to 1 m
  EXPECT_NEAR(in_f1, hand / f1, 2e-3);
  std::printf("ridge: clearance %.3f m printed, %.3f m by hand (F1 %.3f m)\n", clearance, hand, f1);
  EXPECT_NE(r.out.find("\nverdict: obstructed: terrain "), std::string::npos) << r.out;
  // The CSV row at that distance says the same; it sits on the ridge's top.
  bool found = false;
  for (const auto& row : read_csv(csv)) {
    ASSERT_EQ(row.size(), 13u);
    if (std::abs(row[0] - d_km) > 0.0005) continue;  // stdout prints 1 m, the CSV 1 mm
    found = true;
    // By hand again at the CSV's distance (to 1 mm).
    const double dc = row[0] * 1000.0;
    const double bulge_c = dc * (D - dc) / (2.0 * 4.0 / 3.0 * 6371000.0);
    const double hand_c = 30.0 + (10.0 - 30.0) * dc / D - (60.0 + bulge_c);
    EXPECT_NEAR(row[3], 60.0, 1e-3);                                        // ground
    EXPECT_NEAR(row[4], bulge_c, 1e-3);                                     // bulge
    EXPECT_NEAR(row[10], hand_c, 0.002);                                    // clearance
    EXPECT_NEAR(row[7], std::sqrt(299792458.0 / 900e6 * dc * (D - dc) / D), 0.002);  // F1
    std::printf("ridge (CSV): clearance %.3f m, by hand %.4f m\n", row[10], hand_c);
    EXPECT_NEAR(row[9], row[6] - 0.6 * row[7], 2e-3);   // the 60% boundary
    EXPECT_GT(row[12], 0.0);                            // the model's knife edge is here
  }
  EXPECT_TRUE(found);
  // The plot: terrain fill, the sight line, the knife-edge marker, white around.
  const test::Image img = test::read_png(png);
  ASSERT_EQ(img.width, 1200);
  ASSERT_EQ(img.height, 600);
  EXPECT_GT(test::color_share(img, {166, 134, 96}, 12), 0.01);
  EXPECT_GT(test::color_share(img, {200, 30, 30}, 40), 0.0005);
  EXPECT_GT(test::color_share(img, {230, 120, 0}, 40), 0.00005);
  EXPECT_GT(test::color_share(img, {255, 255, 255}, 2), 0.3);
}

// `terravol profile MODEL` against `terravol rf MODEL` (queried with `terravol query`) at the
// same lattice points: the largest difference, in dB.
double worst_difference_from_rf(const std::string& model, const std::string& heights) {
  test::TempDir dir;
  const auto vdb = dir.path() / "rf.vdb";
  // A 0.01-degree lattice, so that its points have short decimal coordinates.
  const auto rf = run_terravol("rf " + model + " --tx 45.5,6.5,30 --dem " + bundled_dem() +
                               " --radius-km 6 --spacing 36 --heights " + heights + " -o " + vdb.string());
  EXPECT_EQ(rf.status, 0) << rf.err;
  const char* points[] = {"45.54,6.57,", "45.47,6.43,", "45.45,6.55,", "45.53,6.44,", "45.5,6.56,"};
  const std::vector<std::string> agl = {"10", "110", "210", "10", "110"};
  double worst = 0.0;
  for (std::size_t k = 0; k < std::size(points); ++k) {
    const std::string to = points[k] + agl[k];
    SCOPED_TRACE(model + " to " + to);
    const auto p = run_terravol("profile " + model + " --from 45.5,6.5,30 --to " + to + " --dem " + bundled_dem() +
                                " --csv " + (dir.path() / "x.csv").string() + " --force");
    EXPECT_EQ(p.status, 0) << p.err;
    const double profile_loss = after(p.out, "  path loss ");
    const auto q = run_terravol("query --volume " + vdb.string() + " --dem " + bundled_dem() + " --at " + to);
    EXPECT_EQ(q.status, 0) << q.err;
    const double rf_loss = std::strtod(q.out.substr(q.out.rfind(',') + 1).c_str(), nullptr);
    EXPECT_TRUE(std::isfinite(profile_loss) && std::isfinite(rf_loss)) << p.out << q.out;
    EXPECT_NEAR(profile_loss, rf_loss, 0.01);  // the target (printed to 0.001 dB)
    worst = std::max(worst, std::abs(profile_loss - rf_loss));
  }
  return worst;
}

TEST(ProfileCli, PathLossEqualsRfAtTheSameLatticePoints) {
  const double worst = worst_difference_from_rf("", "10:210:100");
  std::printf("profile against rf (Deygout): largest difference %.4f dB over 5 lattice points\n", worst);
}

TEST(ProfileCli, ItmPathLossEqualsRfWithItmAtTheSameLatticePoints) {
  const double worst = worst_difference_from_rf("--model itm", "10:210:100");
  std::printf("profile against rf (ITM): largest difference %.4f dB over 5 lattice points\n", worst);
}

// The ITM profile says which model gave its loss: no knife edges, the loss beyond free space.
TEST(ProfileCli, ItmProfileNamesItsModelInTheVerdict) {
  test::TempDir dir;
  const auto r = run_terravol("profile --model itm --from 45.5,6.5,30 --to 45.54,6.57,10 --dem " + bundled_dem() +
                              " --csv " + (dir.path() / "x.csv").string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("dB + ITM beyond free space "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(" dB beyond free space)\n"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("knife edge at"), std::string::npos) << r.out;
}

// Without a display, -o (the plot) fails at once naming the command; the CSV alone needs none.
TEST(ProfileCli, APlotWithoutAnXDisplayFailsNamingProfile) {
  test::TempDir dir;
  const std::string args = "profile --from 45.5,6.5,30 --to 45.54,6.57,10 --dem " + bundled_dem();
  const auto r = test::run_terravol_under("env -u DISPLAY", args + " -o " + (dir.path() / "p.png").string());
  expect_one_line_error(r, "profile -o needs an X display");
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
  const auto csv = test::run_terravol_under("env -u DISPLAY", args + " --csv " + (dir.path() / "p.csv").string());
  EXPECT_EQ(csv.status, 0) << csv.err;
}

TEST(ProfileCli, BadInputFailsWithOneLineAndWritesNothing) {
  test::TempDir dir;
  const std::string dem = " --dem " + bundled_dem();
  const std::string csv = " --csv " + (dir.path() / "x.csv").string();
  const std::pair<std::string, std::string> cases[] = {
      {"--from 45.5,6.5 --to 45.5,6.6,10" + dem + csv, "--from 45.5,6.5: expected LAT,LON,HEIGHT_AGL"},
      {"--from 45.5,6.5,30 --to 45.5,x,10" + dem + csv, "--to 45.5,x,10: expected LAT,LON,HEIGHT_AGL"},
      {"--from 45.5,6.5,30 --to 95,6.6,10" + dem + csv, "--to 95,6.6,10: latitude must be within"},
      {"--from 45.5,6.5,30 --to 45.5,7.6,10" + dem + csv, "--to 45.5,7.6,10: the point lies outside the DEM"},
      {"--from 45.5,6.5,30 --to 45.5,6.5,10" + dem + csv, "--to 45.5,6.5,10: the same point as --from"},
      {"--from 45.5,6.5,30 --to 45.5,6.6,10 --k-factor 4/0" + dem + csv, "--k-factor 4/0: expected a number or a fraction"},
      {"--from 45.5,6.5,30 --to 45.5,6.6,10 --freq 0" + dem + csv, "--freq 0: must be within (0, 100000] MHz"},
      {"--from 45.5,6.5,30,pattern=" + (dir.path() / "no.az").string() + " --to 45.5,6.6,10" + dem + csv,
       "--from 45.5,6.5,30,pattern="},
      {"--from 45.5,6.5,30 --to 45.5,6.6,10" + dem, "give -o PROFILE.png, --csv PROFILE.csv or both"},
      {"--from 45.5,6.5,30 --to 45.5,6.6,10" + dem + " --csv " + (dir.path() / "x.txt").string(), "--csv "},
      {"--from 45.5,6.5,30 --to 45.5,6.6,10" + dem + csv + " --size 10x10", "--size 10x10"},
      {"--from 45.5,6.5,30 --to 45.5,6.6,10 --model foo" + dem + csv, "--model foo: must be itm or deygout"},
      {"--from 45.5,6.5,30 --to 45.5,6.6,10 --climate 5" + dem + csv, "--climate: only with --model itm"},
      {"--from 45.5,6.5,30 --to 45.5,6.6,10 --model itm --edge-depth 3" + dem + csv, "--edge-depth: only with --model deygout"},
      {"--from 45.5,6.5,30 --to 45.5,6.6,10 --model itm --freq 10" + dem + csv,
       "--freq 10: ITM takes frequencies within [20, 20000] MHz"},
      {"--from 45.5,6.5,30 --to 45.5,6.6,0.2 --model itm" + dem + csv,
       "--to 45.5,6.6,0.2: ITM takes antenna heights within [0.5, 3000] m above ground"},
      {"--from 45.5,6.5,30 --to 45.5,6.6,10 --model itm --time 1.5" + dem + csv, "--time 1.5: must be within (0, 1)"},
  };
  for (const auto& [args, prefix] : cases) {
    SCOPED_TRACE(args);
    expect_one_line_error(run_terravol("profile " + args), prefix);
  }
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
  // Never over what is there without --force.
  std::ofstream(dir.path() / "x.csv") << "mine";
  const auto r = run_terravol("profile --from 45.5,6.5,30 --to 45.5,6.6,10" + dem + csv);
  EXPECT_EQ(r.status, 1);
  std::ifstream in(dir.path() / "x.csv");
  std::string kept;
  std::getline(in, kept);
  EXPECT_EQ(kept, "mine");
}

}  // namespace
}  // namespace terravol::app::cli
