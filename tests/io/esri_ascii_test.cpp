#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <string>

#include "io/dem_file.h"
#include "io/error.h"
#include "io/readers.h"
#include "parse_check.h"
#include "shared_data.h"

namespace terravol::io {
namespace {

Grid parse(const std::string& text, std::optional<UtmZone> zone = std::nullopt,
           const std::string& prj = "") {
  return parse_esri_ascii(text, "t.asc", zone, prj);
}

// The FormatError message of parsing text, or "" when it parses.
std::string error_of(const std::string& text, std::optional<UtmZone> zone = std::nullopt,
                     const std::string& prj = "") {
  try {
    parse(text, zone, prj);
  } catch (const FormatError& e) {
    return e.what();
  }
  return "";
}

// 3 columns x 2 rows of degrees at 0.5 degree spacing, lower-left corner 10 E, 40 N.
const std::string kSmall =
    "ncols 3\n"
    "nrows 2\n"
    "xllcorner 10\n"
    "yllcorner 40\n"
    "cellsize 0.5\n"
    "NODATA_value -9999\n"
    "1 2 3\n"
    "4 -9999 6.5\n";

TEST(EsriAscii, FirstRowIsNorthAndNodataBecomesVoid) {
  const Grid g = parse(kSmall);
  EXPECT_EQ(g.format, "esri-ascii");
  ASSERT_EQ(g.rows, 2);
  ASSERT_EQ(g.cols, 3);
  EXPECT_EQ(g.heights[g.index(0, 0)], 1.0f);
  EXPECT_EQ(g.heights[g.index(0, 2)], 3.0f);
  EXPECT_EQ(g.heights[g.index(1, 0)], 4.0f);
  EXPECT_EQ(g.heights[g.index(1, 2)], 6.5f);
  EXPECT_EQ(g.mask[g.index(1, 1)], Sample::kVoid);
  EXPECT_EQ(count(g, Sample::kVoid), 1u);
  EXPECT_EQ(g.vertical_datum, "unknown (ESRI ASCII grid does not say)");
}

TEST(EsriAscii, CornerRegistrationMovesSamplesHalfACellIn) {
  const Grid g = parse(kSmall);
  EXPECT_EQ(g.georef.crs, Crs::kGeographic);
  EXPECT_DOUBLE_EQ(g.georef.x0, 10.25);
  EXPECT_DOUBLE_EQ(g.georef.y0, 40.0 + 1.5 * 0.5);
  EXPECT_DOUBLE_EQ(g.georef.dx, 0.5);
  EXPECT_DOUBLE_EQ(g.georef.dy, 0.5);
}

TEST(EsriAscii, CenterRegistrationKeepsSamplePositions) {
  const Grid g =
      parse("ncols 3\nnrows 2\nxllcenter 10\nyllcenter 40\ncellsize 0.5\n1 2 3\n4 5 6\n");
  EXPECT_DOUBLE_EQ(g.georef.x0, 10.0);
  EXPECT_DOUBLE_EQ(g.georef.y0, 40.5);
  EXPECT_EQ(count(g, Sample::kVoid), 0u);
}

TEST(EsriAscii, HeaderKeysAreCaseInsensitiveInAnyOrderWithCrLf) {
  const Grid g = parse(
      "CELLSIZE 0.5\r\nNROWS 2\r\nxLLcorner 10\r\nNCols 3\r\nYLLCORNER 40\r\n"
      "nodata_value 5\r\n 1 2 3\r\n 4 5 6\r\n");
  ASSERT_EQ(g.cols, 3);
  EXPECT_DOUBLE_EQ(g.georef.x0, 10.25);
  EXPECT_EQ(g.mask[g.index(1, 1)], Sample::kVoid);
  EXPECT_EQ(g.heights[g.index(1, 2)], 6.0f);
}

TEST(EsriAscii, SeparateDxDyGiveRectangularCells) {
  const Grid g = parse("ncols 2\nnrows 2\nxllcorner 0\nyllcorner 0\ndx 0.2\ndy 0.1\n1 2\n3 4\n");
  EXPECT_DOUBLE_EQ(g.georef.dx, 0.2);
  EXPECT_DOUBLE_EQ(g.georef.dy, 0.1);
  EXPECT_DOUBLE_EQ(g.georef.x0, 0.1);
  EXPECT_DOUBLE_EQ(g.georef.y0, 0.15);
}

TEST(EsriAscii, RowsMayWrapOverLines) {
  const Grid g =
      parse("ncols 3\nnrows 2\nxllcorner 10\nyllcorner 40\ncellsize 0.5\n1 2\n3\n4\n5 6\n");
  EXPECT_EQ(g.heights[g.index(0, 2)], 3.0f);
  EXPECT_EQ(g.heights[g.index(1, 0)], 4.0f);
  EXPECT_EQ(g.heights[g.index(1, 2)], 6.0f);
}

const std::string kUtmHeader =
    "ncols 2\nnrows 2\nxllcorner 500000\nyllcorner 4000000\ncellsize 30\n1 2\n3 4\n";

TEST(EsriAscii, MetresWithoutAZoneAreRejected) {
  EXPECT_EQ(error_of(kUtmHeader),
            "t.asc: coordinates are not degrees; give the projection with a .prj beside the file "
            "or --crs utm:ZZN");
  // A one-degree cell is not taken for degrees either.
  EXPECT_NE(error_of("ncols 2\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2\n3 4\n"), "");
  // Nor an extent past the poles.
  EXPECT_NE(error_of("ncols 2\nnrows 200\nxllcorner 0\nyllcorner 0\ncellsize 0.5\n" +
                     std::string(1000, '\n')),
            "");
}

TEST(EsriAscii, GivenZoneMakesUtmMetres) {
  const Grid g = parse(kUtmHeader, UtmZone{13, true});
  EXPECT_EQ(g.georef.crs, Crs::kUtm);
  EXPECT_EQ(g.georef.utm_zone, 13);
  EXPECT_TRUE(g.georef.utm_north);
  EXPECT_DOUBLE_EQ(g.georef.x0, 500015.0);
  EXPECT_DOUBLE_EQ(g.georef.y0, 4000045.0);
}

TEST(EsriAscii, PrjZoneMakesUtmAndGivenZoneOverridesIt) {
  const std::string prj = R"(PROJCS["WGS_1984_UTM_Zone_25S",GEOGCS["GCS_WGS_1984"]])";
  Grid g = parse(kUtmHeader, std::nullopt, prj);
  EXPECT_EQ(g.georef.crs, Crs::kUtm);
  EXPECT_EQ(g.georef.utm_zone, 25);
  EXPECT_FALSE(g.georef.utm_north);
  ASSERT_EQ(g.notes.size(), 1u);
  EXPECT_EQ(g.notes[0], "UTM zone 25S from the .prj file");
  g = parse(kUtmHeader, UtmZone{10, true}, prj);
  EXPECT_EQ(g.georef.utm_zone, 10);
  EXPECT_TRUE(g.georef.utm_north);
}

TEST(EsriAscii, NonUtmPrjIsRejectedByName) {
  const std::string prj = R"(PROJCS["NAD_1983_StatePlane_Colorado_North_FIPS_0501",GEOGCS["x"]])";
  EXPECT_EQ(
      error_of(kUtmHeader, std::nullopt, prj),
      "t.asc: the .prj names projection 'NAD_1983_StatePlane_Colorado_North_FIPS_0501', which "
      "is not UTM; only geographic and UTM grids are read (override with --crs utm:ZZN)");
  // A geographic .prj is fine for degrees.
  EXPECT_EQ(error_of(kSmall, std::nullopt, R"(GEOGCS["GCS_WGS_1984",DATUM["D_WGS_1984"]])"), "");
}

TEST(EsriAscii, ShortRowNamesLineAndRow) {
  EXPECT_EQ(
      error_of("ncols 3\nnrows 3\nxllcorner 10\nyllcorner 40\ncellsize 0.5\n1 2 3\n4 5\n7 8 9\n"),
      "t.asc: line 7: expected 3 values in row 2, found 2");
  EXPECT_EQ(error_of("ncols 3\nnrows 3\nxllcorner 10\nyllcorner 40\ncellsize 0.5\n1 2 3\n4 5 6\n7"),
            "t.asc: line 8: expected 3 values in row 3, found 1");
  EXPECT_EQ(
      error_of("ncols 3\nnrows 3\nxllcorner 10\nyllcorner 40\ncellsize 0.5\n1 2 3\n4 5 6 7\n8 9\n"),
      "t.asc: line 7: row 2 has more than 3 values");
  EXPECT_EQ(error_of("ncols 3\nnrows 3\nxllcorner 10\nyllcorner 40\ncellsize 0.5\n1 2 3\n"),
            "t.asc: the file ends after line 6, before row 2 of 3");
}

TEST(EsriAscii, ExtraDataAfterTheLastRowIsRejected) {
  EXPECT_EQ(error_of(kSmall + "7 8 9\n"),
            "t.asc: line 9: more data after the 2 rows the header gives");
  EXPECT_EQ(error_of(kSmall + "\n  \n"), "");
}

TEST(EsriAscii, BadValuesAndHeadersAreRejected) {
  EXPECT_EQ(error_of("ncols 3\nnrows 2\nxllcorner 10\nyllcorner 40\ncellsize 0.5\n1 2 x\n4 5 6\n"),
            "t.asc: line 6: 'x' in row 1 is not a number");
  EXPECT_EQ(
      error_of("ncols 3\nnrows 2\nxllcorner 10\nyllcorner 40\ncellsize 0.5\n1 2 nan\n4 5 6\n"),
      "t.asc: line 6: 'nan' in row 1 is not a number");
  EXPECT_EQ(
      error_of("ncols 3\nnrows 2\nxllcorner 10\nyllcorner 40\ncellsize 0.5\n1 2 1e39\n4 5 6\n"),
      "t.asc: line 6: '1e39' in row 1 is out of range");
  EXPECT_EQ(error_of("ncols 3\nnrows 2\nxllcorner 10\nyllcorner 40\ncolour blue\n"),
            "t.asc: line 5: unknown header key 'colour'");
  EXPECT_EQ(error_of("ncols 3\nnrows 2\nxllcorner 10\nxllcenter 10\n"),
            "t.asc: line 4: header key 'xllcenter' given twice (or with its corner/center twin)");
  EXPECT_EQ(error_of("ncols 3.5\n"), "t.asc: line 1: 'ncols' value '3.5' is not an integer");
  EXPECT_EQ(error_of("ncols\n"), "t.asc: line 1: header key 'ncols' has no value");
  EXPECT_EQ(error_of("nrows 2\nxllcorner 10\nyllcorner 40\ncellsize 0.5\n1 2\n"),
            "t.asc: header has no ncols");
  EXPECT_EQ(error_of("ncols 2\nnrows 2\nxllcorner 10\nyllcorner 40\ncellsize 0\n1 2\n3 4\n"),
            "t.asc: cell size is not positive");
  EXPECT_EQ(error_of(""), "t.asc: the file ends in the header, before any data");
  EXPECT_EQ(error_of("ncols 0\nnrows 2\nxllcorner 10\nyllcorner 40\ncellsize 0.5\n1 2\n"),
            "t.asc: grid of 2 x 0 samples is empty or negative");
}

TEST(EsriAscii, HugeDimensionsFailAtOnce) {
  EXPECT_EQ(
      error_of(
          "ncols 1000000000\nnrows 1000000000\nxllcorner 10\nyllcorner 40\ncellsize 0.5\n1 2\n"),
      "t.asc: grid of 1000000000 x 1000000000 samples is absurdly large");
  EXPECT_EQ(error_of("ncols 1000\nnrows 1000\nxllcorner 10\nyllcorner 40\ncellsize 0.0005\n1 2\n"),
            "t.asc: header claims 1000 x 1000 samples but the file holds at most 34");
}

std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(EsriAscii, ReadsTheFrontRange) {
  const auto path = test::shared_dem("front_range_srtmgl3.asc");
  TERRAVOL_REQUIRE_SHARED(path);
  const Grid g = read_dem(path);
  EXPECT_EQ(g.rows, 758);
  EXPECT_EQ(g.cols, 758);
  EXPECT_EQ(g.georef.crs, Crs::kGeographic);
  const double cell = 0.000833333333;
  EXPECT_DOUBLE_EQ(g.georef.dx, cell);
  EXPECT_DOUBLE_EQ(g.georef.x0, -105.816250000017 + cell / 2);
  EXPECT_DOUBLE_EQ(g.georef.y0, 39.834583333338 + 757.5 * cell);
  const auto r = height_range(g);
  EXPECT_EQ(r.min, 1547.0f);
  EXPECT_EQ(r.max, 4320.0f);
  // NODATA_value is 0 and no sample is 0: SRTMGL3 has no voids here.
  EXPECT_EQ(count(g, Sample::kVoid), 0u);
  EXPECT_EQ(g.heights[g.index(0, 0)], 3362.0f);
  EXPECT_EQ(g.heights[g.index(757, 757)], 1731.0f);
}

TEST(EsriAscii, EveryTruncationFailsCleanlyOrParses) {
  auto check = [](const std::string& text, std::size_t step) {
    test::expect_prefixes_handled([](const std::string& t) { return parse(t); }, text, step, "t.asc");
  };
  check(kSmall, 1);
  const auto path = test::shared_dem("front_range_srtmgl3.asc");
  TERRAVOL_REQUIRE_SHARED(path);
  const std::string text = read_file(path);
  check(text, 9973);
  // Cut within the last row (line 764: 6 header lines, then 758 rows).
  EXPECT_EQ(error_of(text.substr(0, text.size() - 1000))
                .rfind("t.asc: line 764: expected 758 values in row 758, found ", 0),
            0u);
  // Cut early, the file cannot hold the samples its header claims.
  EXPECT_EQ(error_of(text.substr(0, 10000)),
            "t.asc: header claims 758 x 758 samples but the file holds at most 5000");
}

TEST(EsriAscii, ShortRowOfTheFrontRangeNamesLineAndRow) {
  const auto path = test::shared_dem("front_range_srtmgl3.asc");
  TERRAVOL_REQUIRE_SHARED(path);
  std::string text = read_file(path);
  // Keep the first 12 values of line 9 (row 3).
  std::size_t line9 = 0;
  for (int i = 0; i < 8; ++i) line9 = text.find('\n', line9) + 1;
  std::size_t cut = line9;
  for (int i = 0; i < 13; ++i) cut = text.find_first_not_of(' ', text.find(' ', cut));
  text.erase(cut, text.find('\n', line9) - cut);
  EXPECT_EQ(error_of(text), "t.asc: line 9: expected 758 values in row 3, found 12");
}

TEST(EsriUtmZone, ParsesZoneAndHemisphere) {
  auto z = parse_utm_zone("utm:10N");
  ASSERT_TRUE(z);
  EXPECT_EQ(z->zone, 10);
  EXPECT_TRUE(z->north);
  z = parse_utm_zone("UTM:25s");
  ASSERT_TRUE(z);
  EXPECT_EQ(z->zone, 25);
  EXPECT_FALSE(z->north);
  z = parse_utm_zone("utm:1n");
  ASSERT_TRUE(z);
  EXPECT_EQ(z->zone, 1);
  EXPECT_TRUE(parse_utm_zone("utm:60S"));
}

TEST(EsriUtmZone, RejectsMalformedZones) {
  for (const char* bad : {"utm:0N", "utm:61N", "utm:10", "utm:10X", "utm10N", "utm:+1N", "utm:-5S",
                          "utm:100N", "utm:N", " utm:10N", "utm:10N ", "geo:10N", ""}) {
    EXPECT_FALSE(parse_utm_zone(bad)) << bad;
  }
}

TEST(EsriPrjZone, ReadsWktNames) {
  auto z = utm_zone_from_prj(
      R"(PROJCS["WGS_1984_UTM_Zone_10N",GEOGCS["GCS_WGS_1984",DATUM["D_WGS_1984"]],PROJECTION["Transverse_Mercator"]])");
  ASSERT_TRUE(z);
  EXPECT_EQ(z->zone, 10);
  EXPECT_TRUE(z->north);
  z = utm_zone_from_prj(R"(PROJCS["WGS 84 / UTM zone 25S",GEOGCS["WGS 84"]])");
  ASSERT_TRUE(z);
  EXPECT_EQ(z->zone, 25);
  EXPECT_FALSE(z->north);
  z = utm_zone_from_prj(R"(PROJCS["UTM Zone 33, Southern Hemisphere",GEOGCS["x"]])");
  ASSERT_TRUE(z);
  EXPECT_EQ(z->zone, 33);
  EXPECT_FALSE(z->north);
  // No hemisphere letter: the false northing decides.
  z = utm_zone_from_prj(R"(PROJCS["UTM zone 18",PARAMETER["False_Northing",10000000.0]])");
  ASSERT_TRUE(z);
  EXPECT_FALSE(z->north);
}

TEST(EsriPrjZone, ReadsTheOldEsriForm) {
  auto z = utm_zone_from_prj(
      "Projection    UTM\nZone          13\nDatum         NAD83\nUnits         METERS\n");
  ASSERT_TRUE(z);
  EXPECT_EQ(z->zone, 13);
  EXPECT_TRUE(z->north);
  z = utm_zone_from_prj("Projection UTM\r\nZone -23\r\n");
  ASSERT_TRUE(z);
  EXPECT_EQ(z->zone, 23);
  EXPECT_FALSE(z->north);
  z = utm_zone_from_prj("projection utm\nzone 36\nyshift 10000000\n");
  ASSERT_TRUE(z);
  EXPECT_FALSE(z->north);
}

TEST(EsriPrjZone, OtherProjectionsAreNotUtm) {
  EXPECT_FALSE(utm_zone_from_prj(R"(GEOGCS["GCS_WGS_1984",DATUM["D_WGS_1984"]])"));
  EXPECT_FALSE(utm_zone_from_prj(R"(PROJCS["NAD_1983_StatePlane_Colorado_North_FIPS_0501"])"));
  EXPECT_FALSE(utm_zone_from_prj("Projection GEOGRAPHIC\n"));
  EXPECT_FALSE(utm_zone_from_prj("Projection UTM\nZone 0\n"));
  EXPECT_FALSE(utm_zone_from_prj("Projection UTM\nZone 61\n"));
  EXPECT_FALSE(utm_zone_from_prj(R"(PROJCS["WGS_1984_UTM_Zone_99N"])"));
  EXPECT_FALSE(utm_zone_from_prj(R"(PROJCS[")"));
  EXPECT_FALSE(utm_zone_from_prj(""));
}

}  // namespace
}  // namespace terravol::io
