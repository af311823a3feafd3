// `terravol info` as a user runs it: real files, the bundled DEM, and bad input.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fstream>

#include "compress.h"
#include "io/compressed.h"
#include "io/dem_file.h"
#include "run_command.h"
#include "shared_data.h"

namespace terravol {
namespace {

using test::run_terravol;

nlohmann::json info_json(const std::string& path) {
  const auto r = run_terravol("info --json " + path, 120);  // the Utah tiles take 5-30 s under load
  EXPECT_EQ(r.status, 0) << r.err;
  return nlohmann::json::parse(r.out);
}

TEST(InfoCli, HelpListsTheSubcommands) {
  const auto r = run_terravol("--help");
  EXPECT_EQ(r.status, 0);
  EXPECT_NE(r.out.find("info"), std::string::npos);
  EXPECT_NE(r.out.find("sample-dem"), std::string::npos);
  EXPECT_EQ(run_terravol("info --help").status, 0);
}

TEST(InfoCli, BundledDemIsDescribedInTextAndJson) {
  const std::string dem = std::string(TERRAVOL_SOURCE_DIR) + "/data/dem/N45E006.hgt";
  const auto r = run_terravol("info " + dem);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("45.000000 N .. 46.000000 N, 6.000000 E .. 7.000000 E"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("36 (36 samples filled for rendering)"), std::string::npos) << r.out;
  const auto j = info_json(dem);
  for (const char* key : {"format", "rows", "cols", "south", "north", "west", "east", "min_elevation",
                          "max_elevation", "voids", "tiles"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(j["rows"], 1201);
  EXPECT_EQ(j["voids"], 36);
}

std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

TEST(InfoCli, SampleDemIsRegeneratedByteForByte) {
  test::TempDir dir;
  const auto r = run_terravol("sample-dem -o " + dir.path().string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(slurp(dir.path() / "N45E006.hgt"), slurp(std::string(TERRAVOL_SOURCE_DIR) + "/data/dem/N45E006.hgt"));
  const auto again = run_terravol("sample-dem -o " + dir.path().string());
  EXPECT_EQ(again.status, 1) << "an existing file is not overwritten without --force";
}

TEST(InfoCli, SampleDemTilesMakeOneSeamlessMosaicWhoseFirstTileIsTheBundledOne) {
  test::TempDir dir;
  const auto r = run_terravol("sample-dem --tiles 2x2 -o " + dir.path().string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(slurp(dir.path() / "N45E006.hgt"), slurp(std::string(TERRAVOL_SOURCE_DIR) + "/data/dem/N45E006.hgt"));
  // Neighbours share their edge samples (big-endian int16, row 0 north): N46E006's south row is
  // N45E006's north row, N45E007's west column is N45E006's east column.
  const std::string sw = slurp(dir.path() / "N45E006.hgt"), nw = slurp(dir.path() / "N46E006.hgt");
  const std::string se = slurp(dir.path() / "N45E007.hgt");
  ASSERT_EQ(nw.size(), 1201u * 1201u * 2u);
  EXPECT_EQ(nw.substr(1200u * 1201u * 2u), sw.substr(0, 1201u * 2u));
  for (std::size_t row = 0; row < 1201; row += 100)
    EXPECT_EQ(se.substr(row * 1201 * 2, 2), sw.substr((row * 1201 + 1200) * 2, 2)) << row;
  EXPECT_NE(nw, sw);
  const auto j = info_json((dir.path() / "N45E006.hgt").string() + " " + (dir.path() / "N46E006.hgt").string() + " " +
                           (dir.path() / "N45E007.hgt").string() + " " + (dir.path() / "N46E007.hgt").string());
  EXPECT_EQ(j["rows"], 2401);
  EXPECT_EQ(j["cols"], 2401);
  const auto bad = run_terravol("sample-dem --tiles 0x3 -o " + dir.path().string());
  EXPECT_NE(bad.status, 0) << "CLI11's validation status";
  EXPECT_NE(bad.err.find("--tiles"), std::string::npos) << bad.err;
}

// The table of ../shared/data/README.md: grid, bounds and elevation range of each file.
struct Expected {
  const char* file;
  int rows, cols;
  double south, north, west, east, min_h, max_h;
  double bounds_tolerance;
};

void PrintTo(const Expected& e, std::ostream* os) { *os << e.file; }

class InfoOnSharedData : public ::testing::TestWithParam<Expected> {};

TEST_P(InfoOnSharedData, ReportsTheGridBoundsAndElevationRangeOfTheDataTable) {
  const Expected e = GetParam();
  const auto path = test::shared_dem(e.file);
  TERRAVOL_REQUIRE_SHARED(path);
  const auto j = info_json(path.string());
  const auto& t = j["tiles"][0];
  EXPECT_EQ(t["rows"], e.rows);
  EXPECT_EQ(t["cols"], e.cols);
  EXPECT_NEAR(t["south"].get<double>(), e.south, e.bounds_tolerance);
  EXPECT_NEAR(t["north"].get<double>(), e.north, e.bounds_tolerance);
  EXPECT_NEAR(t["west"].get<double>(), e.west, e.bounds_tolerance);
  EXPECT_NEAR(t["east"].get<double>(), e.east, e.bounds_tolerance);
  EXPECT_EQ(t["min_elevation"].get<double>(), e.min_h);
  EXPECT_EQ(t["max_elevation"].get<double>(), e.max_h);
}

TEST(InfoCli, SaintHelensHasThe148885SamplesOfItsProfilesAndSaysItWasResampled) {
  const auto path = test::shared_dem("SainteHelens.dem");
  TERRAVOL_REQUIRE_SHARED(path);
  const auto j = info_json(path.string());
  const auto& t = j["tiles"][0];
  EXPECT_EQ(t["valid_samples"], 148885);
  EXPECT_EQ(t["projection"]["zone"], 10);
  EXPECT_EQ(t["projection"]["hemisphere"], "N");
  bool resampled = false;
  for (const auto& note : t["notes"]) resampled |= note.get<std::string>().find("resampled bilinearly") != std::string::npos;
  EXPECT_TRUE(resampled);
}

INSTANTIATE_TEST_SUITE_P(
    DataTable, InfoOnSharedData,
    ::testing::Values(Expected{"N44W072.hgt", 1201, 1201, 44, 45, -72, -71, 115, 1908, 1e-9},
                      Expected{"N22W160.hgt", 1201, 1201, 22, 23, -160, -159, -34, 1579, 1e-9},
                      Expected{"S46W066.hgt.gz", 3601, 3601, -46, -45, -66, -65, -3, 146, 1e-9},
                      Expected{"n33_w116_3arc_v2.dt1", 1201, 1201, 33, 34, -116, -115, -87, 1619, 1e-9},
                      Expected{"front_range_srtmgl3.asc", 758, 758, 39.835, 40.466, -105.816, -105.185, 1547, 4320, 0.002},
                      // Projected files: the native grid, and the bounds of their geographic presentation.
                      Expected{"SainteHelens.dem", 466, 327, 46.1224, 46.2488, -122.2516, -122.1234, 682, 2543, 0.001},
                      Expected{"olinda_dem_utm25s.tif", 111, 111, -8.0397, -7.9502, -34.9162, -34.8264, -1, 88, 0.001}),
    [](const auto& param_info) {
      std::string name = param_info.param.file;
      for (char& c : name)
        if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
      return name;
    });

TEST(InfoCli, UtahSdfDirectoryIsOneMosaic) {
  const auto dir = test::shared_dem("utah_sdf");
  TERRAVOL_REQUIRE_SHARED(dir);
  const auto j = info_json(dir.string());
  EXPECT_EQ(j["tiles"].size(), 6u);
  EXPECT_EQ(j["rows"], 2400);
  EXPECT_EQ(j["cols"], 3600);
  EXPECT_NEAR(j["south"].get<double>(), 40.0, 1e-9);
  EXPECT_NEAR(j["west"].get<double>(), -113.0, 1e-9);
  EXPECT_NEAR(j["north"].get<double>(), 42.0, 1.0 / 1200 + 1e-9);
  EXPECT_NEAR(j["east"].get<double>(), -110.0, 1.0 / 1200 + 1e-9);
  EXPECT_EQ(j["min_elevation"], 1242);
  EXPECT_EQ(j["max_elevation"], 4111);
  EXPECT_EQ(j["gap_samples"], 0);
}

// SPLAT! terrain as meshtastic-site-planner ships it: gzip-compressed SDF tiles in a folder.
TEST(InfoCli, GzippedSdfTilesAndTheirFolderReadLikeTheOriginals) {
  const auto a = test::shared_dem("utah_sdf/40_41_111_112.sdf.bz2"), b = test::shared_dem("utah_sdf/40_41_112_113.sdf.bz2");
  TERRAVOL_REQUIRE_SHARED(a);
  TERRAVOL_REQUIRE_SHARED(b);
  test::TempDir dir;
  for (const auto& p : {a, b}) {
    const std::string name(io::strip_compression(p.filename().string()));
    test::write_file_bytes(dir.path() / (name + ".gz"), test::gzip_bytes(io::read_content(p)));
  }
  const auto tile = dir.path() / "40_41_111_112.sdf.gz";
  const auto r = run_terravol("info " + tile.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("SPLAT! SDF, gzip-compressed"), std::string::npos) << r.out;
  auto gz = info_json(tile.string())["tiles"][0], bz2 = info_json(a.string())["tiles"][0];
  EXPECT_EQ(gz["compression"], "gzip");
  EXPECT_EQ(bz2["compression"], "bzip2");
  for (auto* j : {&gz, &bz2}) {
    j->erase("path");
    j->erase("compression");
  }
  EXPECT_EQ(gz, bz2);
  auto folder = info_json(dir.path().string()), originals = info_json(a.string() + " " + b.string());
  EXPECT_EQ(folder["tiles"].size(), 2u);
  EXPECT_EQ(folder["rows"], 1200);
  EXPECT_EQ(folder["cols"], 2400);
  EXPECT_EQ(folder["gap_samples"], 0);
  folder.erase("tiles");
  originals.erase("tiles");
  EXPECT_EQ(folder, originals);
}

// Bad input: one line "terravol: FILE: what is wrong", exit status 1 or 2, and no hang (the
// 10 s bound is a hang guard; it takes about 0.1 s, more under load).
void expect_clean_failure(const std::string& args, const std::string& must_mention) {
  const auto r = run_terravol(args);
  EXPECT_TRUE(r.status == 1 || r.status == 2) << args << " exited " << r.status << "\n" << r.err;
  EXPECT_LT(r.seconds, 10.0) << args;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find(must_mention), std::string::npos) << r.err;
}

TEST(InfoCli, BadInputFailsCleanlyWithOneLine) {
  test::TempDir dir;
  const auto p = [&](const char* name) { return (dir.path() / name).string(); };
  std::ofstream(p("N10E010.hgt"), std::ios::binary) << std::string(1000, '\0');
  std::ofstream(p("garbage.dt1"), std::ios::binary) << std::string(5000, 'x');
  std::ofstream(p("huge.asc")) << "ncols 1000000000\nnrows 1000000000\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2 3\n";
  std::ofstream(p("trunc.asc")) << "ncols 3\nnrows 3\nxllcorner 0\nyllcorner 0\ncellsize 0.1\n1 2 3\n4 5\n";
  std::ofstream(p("junk.tif")) << "II*\0garbage";
  std::ofstream(p("short.hgt.gz")) << "\x1f\x8b\x08\x00";
  std::ofstream(p("notes.txt")) << "hello";
  std::ofstream(p("40_41_111_112.sdf.gz")) << "BZh91AY&SY";
  std::ofstream(p("cut.sdf.xz"), std::ios::binary) << std::string("\xfd" "7zXZ\0\0\4", 8);
  std::ofstream(p("junk.dt1.zip")) << "PK\3\4 not really";
  expect_clean_failure("info " + p("N10E010.hgt"), "N10E010.hgt: size 1000 bytes");
  expect_clean_failure("info " + p("garbage.dt1"), "garbage.dt1: ");
  expect_clean_failure("info " + p("huge.asc"), "huge.asc: ");
  expect_clean_failure("info " + p("trunc.asc"), "trunc.asc: ");
  expect_clean_failure("info " + p("junk.tif"), "junk.tif: ");
  expect_clean_failure("info " + p("short.hgt.gz"), "short.hgt.gz: ");
  expect_clean_failure("info " + p("notes.txt"), "notes.txt: unknown DEM format");
  expect_clean_failure("info " + p("40_41_111_112.sdf.gz"), "40_41_111_112.sdf.gz: named .gz but holds bzip2 data");
  expect_clean_failure("info " + p("cut.sdf.xz"), "cut.sdf.xz: xz data is truncated");
  expect_clean_failure("info " + p("junk.dt1.zip"), "junk.dt1.zip: not a readable zip archive");
  expect_clean_failure("info " + p("missing.hgt"), "missing.hgt: ");
  expect_clean_failure("info --crs utm:99X " + p("trunc.asc"), "--crs");
}

}  // namespace
}  // namespace terravol
