#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "io/dem_file.h"
#include "io/error.h"
#include "io/readers.h"
#include "parse_check.h"
#include "shared_data.h"

namespace terravol::io {
namespace {

// A profile of a synthetic DEM: planimetric coordinates of its first (southern) elevation,
// its local datum elevation and its raw I6 values, south to north.
struct TestProfile {
  double x = 0.0;
  double y = 0.0;
  double datum = 0.0;
  std::vector<int> values;
};

struct TestDem {
  int ref_system = 1;  // 0 geographic, 1 UTM
  int zone = 10;
  int plan_units = 2;  // 3 arc-seconds, 2 metres
  int elev_units = 2;  // 1 feet, 2 metres
  double res_x = 30.0, res_y = 30.0, res_z = 1.0;
  std::string vertical_datum_code;  // "" leaves bytes 889-890 blank
  std::vector<TestProfile> profiles;
};

// Writes `text` right-aligned into the 1-based byte columns first..last of a record.
void put(std::string& record, int first, int last, const std::string& text) {
  const auto width = static_cast<std::size_t>(last - first + 1);
  ASSERT_LE(text.size(), width) << text;
  record.replace(static_cast<std::size_t>(last) - text.size(), text.size(), text);
}

std::string d24(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%24.15E", v);
  std::string s = buf;
  for (char& c : s) {
    if (c == 'E') c = 'D';
  }
  return s;
}

std::string i6(long long v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%6lld", v);
  return buf;
}

std::string type_a(const TestDem& dem) {
  std::string a(1024, ' ');
  put(a, 1, 40, "SYNTHETIC TEST DEM");
  put(a, 145, 150, i6(1));
  put(a, 151, 156, i6(1));
  put(a, 157, 162, i6(dem.ref_system));
  put(a, 163, 168, i6(dem.zone));
  for (int i = 0; i < 15; ++i) put(a, 169 + 24 * i, 192 + 24 * i, d24(0.0));
  put(a, 529, 534, i6(dem.plan_units));
  put(a, 535, 540, i6(dem.elev_units));
  put(a, 541, 546, i6(4));
  for (int i = 0; i < 8; ++i) put(a, 547 + 24 * i, 570 + 24 * i, d24(0.0));
  put(a, 739, 762, d24(0.0));
  put(a, 763, 786, d24(0.0));
  put(a, 787, 810, d24(0.0));
  put(a, 811, 816, i6(0));
  char res[40];
  std::snprintf(res, sizeof res, "%12.6E%12.6E%12.6E", dem.res_x, dem.res_y, dem.res_z);
  a.replace(816, 36, res);
  put(a, 853, 858, i6(1));
  put(a, 859, 864, i6(static_cast<long long>(dem.profiles.size())));
  if (!dem.vertical_datum_code.empty()) put(a, 889, 890, dem.vertical_datum_code);
  return a;
}

// The spec's layout: 1024-byte records, no line breaks.
std::string fixed_dem(const TestDem& dem) {
  std::string out = type_a(dem);
  for (std::size_t k = 0; k < dem.profiles.size(); ++k) {
    const TestProfile& p = dem.profiles[k];
    std::string b = i6(1) + i6(static_cast<long long>(k + 1)) +
                    i6(static_cast<long long>(p.values.size())) + i6(1) + d24(p.x) + d24(p.y) +
                    d24(p.datum) + d24(0.0) + d24(0.0);
    for (const int v : p.values) {
      if (b.size() % 1024 + 6 > 1024) b.resize(b.size() + 1024 - b.size() % 1024, ' ');
      b += i6(v);
    }
    b.resize((b.size() + 1023) / 1024 * 1024, ' ');
    out += b;
  }
  return out;
}

// A line-oriented variant: Type A and each profile header on a line, elevations ten to a line
// with no blanks between fields.
std::string newline_dem(const TestDem& dem) {
  std::string a = type_a(dem);
  a.resize(900);
  std::string out = a + "\n";
  for (std::size_t k = 0; k < dem.profiles.size(); ++k) {
    const TestProfile& p = dem.profiles[k];
    out += i6(1) + i6(static_cast<long long>(k + 1)) + i6(static_cast<long long>(p.values.size())) +
           i6(1) + d24(p.x) + d24(p.y) + d24(p.datum) + d24(0.0) + d24(0.0) + "\r\n";
    for (std::size_t i = 0; i < p.values.size(); ++i) {
      out += std::to_string(p.values[i]);
      out += (i % 10 == 9 || i + 1 == p.values.size()) ? "\r\n" : " ";
    }
  }
  return out;
}

Bytes bytes_of(const std::string& s) {
  return {reinterpret_cast<const std::uint8_t*>(s.data()), s.size()};
}

Grid parse(const std::string& s) {
  return parse_usgs_dem(bytes_of(s), "t.dem");
}

// The FormatError message of parsing s, or "" when it parses.
std::string error_of(const std::string& s) {
  try {
    parse(s);
  } catch (const FormatError& e) {
    return e.what();
  }
  return "";
}

// Three UTM profiles 30 m apart whose footprints differ, like a quad's edge in UTM:
// column 0 covers northings 1000..1060, column 1 970..1090, column 2 1030..1060.
TestDem utm_dem() {
  TestDem dem;
  dem.profiles = {{500000.0, 1000.0, 0.0, {10, 11, 12}},
                  {500030.0, 970.0, 100.0, {20, 21, 22, 23, 24}},
                  {500060.0, 1030.0, 0.0, {-32767, 31}}};
  return dem;
}

TEST(UsgsDem, ProfilesBecomeColumnsWithOutsideWhereTheyDoNotReach) {
  const Grid g = parse(fixed_dem(utm_dem()));
  EXPECT_EQ(g.format, "usgs-dem");
  ASSERT_EQ(g.rows, 5);
  ASSERT_EQ(g.cols, 3);
  EXPECT_EQ(g.georef.crs, Crs::kUtm);
  EXPECT_EQ(g.georef.utm_zone, 10);
  EXPECT_TRUE(g.georef.utm_north);
  EXPECT_DOUBLE_EQ(g.georef.x0, 500000.0);
  EXPECT_DOUBLE_EQ(g.georef.y0, 1090.0);
  EXPECT_DOUBLE_EQ(g.georef.dx, 30.0);
  EXPECT_DOUBLE_EQ(g.georef.dy, 30.0);
  // Row 0 is northing 1090, row 4 northing 970.
  EXPECT_EQ(g.mask[g.index(0, 0)], Sample::kOutside);
  EXPECT_EQ(g.heights[g.index(1, 0)], 12.0f);
  EXPECT_EQ(g.heights[g.index(3, 0)], 10.0f);
  EXPECT_EQ(g.mask[g.index(4, 0)], Sample::kOutside);
  EXPECT_EQ(g.heights[g.index(0, 1)], 124.0f);  // local datum 100 + 24
  EXPECT_EQ(g.heights[g.index(4, 1)], 120.0f);
  EXPECT_EQ(g.mask[g.index(0, 2)], Sample::kOutside);
  EXPECT_EQ(g.heights[g.index(1, 2)], 31.0f);
  EXPECT_EQ(g.mask[g.index(2, 2)], Sample::kVoid);
  EXPECT_EQ(g.mask[g.index(3, 2)], Sample::kOutside);
  EXPECT_EQ(count(g, Sample::kValid), 9u);
  EXPECT_EQ(count(g, Sample::kVoid), 1u);
  EXPECT_EQ(count(g, Sample::kOutside), 5u);
  EXPECT_EQ(g.vertical_datum, "unknown (USGS DEM, mean sea level)");
}

TEST(UsgsDem, LineBrokenRecordsGiveTheSameGridAsFixedRecords) {
  const Grid fixed = parse(fixed_dem(utm_dem()));
  const Grid lines = parse(newline_dem(utm_dem()));
  EXPECT_EQ(lines.rows, fixed.rows);
  EXPECT_EQ(lines.cols, fixed.cols);
  EXPECT_EQ(lines.heights, fixed.heights);
  EXPECT_EQ(lines.mask, fixed.mask);
  EXPECT_DOUBLE_EQ(lines.georef.y0, fixed.georef.y0);
}

TEST(UsgsDem, GluedNegativeFieldsAreSeparated) {
  TestDem dem = utm_dem();
  std::string text = newline_dem(dem);
  // "-32767 31" written as I6 fields without blanks between them.
  const auto at = text.find("-32767 31");
  ASSERT_NE(at, std::string::npos);
  text.replace(at, 9, "-32767-32767");
  const Grid g = parse(text);
  EXPECT_EQ(g.mask[g.index(1, 2)], Sample::kVoid);
  EXPECT_EQ(g.mask[g.index(2, 2)], Sample::kVoid);
}

TEST(UsgsDem, LongProfilesContinueInFurtherRecords) {
  TestDem dem;
  std::vector<int> values(400);
  for (std::size_t i = 0; i < values.size(); ++i) values[i] = static_cast<int>(i);
  dem.profiles = {{300000.0, 6000.0, 0.0, values}, {300030.0, 6000.0, 0.0, values}};
  const std::string text = fixed_dem(dem);
  EXPECT_EQ(text.size(), 1024u * 7);  // Type A + 3 records per profile (146 + 170 + 84)
  const Grid g = parse(text);
  ASSERT_EQ(g.rows, 400);
  for (const int c : {0, 1}) {
    EXPECT_EQ(g.heights[g.index(399, c)], 0.0f);
    EXPECT_EQ(g.heights[g.index(399 - 146, c)], 146.0f);
    EXPECT_EQ(g.heights[g.index(399 - 316, c)], 316.0f);
    EXPECT_EQ(g.heights[g.index(0, c)], 399.0f);
  }
}

TEST(UsgsDem, GeographicArcSecondsAndFeetBecomeDegreesAndMetres) {
  TestDem dem;
  dem.ref_system = 0;
  dem.zone = 0;
  dem.plan_units = 3;
  dem.elev_units = 1;
  dem.res_x = dem.res_y = 3.0;
  dem.res_z = 1.0;
  dem.vertical_datum_code = " 2";
  // 72 W, 44 N, two profiles of three samples, 3" apart.
  dem.profiles = {{-259200.0, 158400.0, 1000.0, {0, 10, 20}},
                  {-259197.0, 158400.0, 1000.0, {30, -32767, 50}}};
  const Grid g = parse(fixed_dem(dem));
  EXPECT_EQ(g.georef.crs, Crs::kGeographic);
  ASSERT_EQ(g.rows, 3);
  ASSERT_EQ(g.cols, 2);
  EXPECT_DOUBLE_EQ(g.georef.x0, -72.0);
  EXPECT_DOUBLE_EQ(g.georef.y0, (158400.0 + 6.0) / 3600.0);
  EXPECT_DOUBLE_EQ(g.georef.dx, 3.0 / 3600.0);
  EXPECT_DOUBLE_EQ(g.georef.dy, 3.0 / 3600.0);
  EXPECT_FLOAT_EQ(g.heights[g.index(2, 0)], 1000.0f * 0.3048f);
  EXPECT_FLOAT_EQ(g.heights[g.index(0, 0)], 1020.0f * 0.3048f);
  EXPECT_FLOAT_EQ(g.heights[g.index(2, 1)], 1030.0f * 0.3048f);
  EXPECT_EQ(g.mask[g.index(1, 1)], Sample::kVoid);
  EXPECT_EQ(count(g, Sample::kOutside), 0u);
  EXPECT_EQ(g.vertical_datum, "NGVD 29");
}

TEST(UsgsDem, ZResolutionScalesValuesAboveTheLocalDatum) {
  TestDem dem = utm_dem();
  dem.res_z = 0.1;
  const Grid g = parse(fixed_dem(dem));
  EXPECT_FLOAT_EQ(g.heights[g.index(0, 1)], 102.4f);
  EXPECT_FLOAT_EQ(g.heights[g.index(3, 0)], 1.0f);
}

TEST(UsgsDem, NegativeZoneMeansSouthernHemisphere) {
  TestDem dem = utm_dem();
  dem.zone = -25;
  const Grid g = parse(fixed_dem(dem));
  EXPECT_EQ(g.georef.utm_zone, 25);
  EXPECT_FALSE(g.georef.utm_north);
  EXPECT_DOUBLE_EQ(g.georef.y0, 1090.0);
}

TEST(UsgsDem, NegativeNorthingsAreSouthWithFalseNorthingAdded) {
  TestDem dem = utm_dem();
  for (auto& p : dem.profiles) p.y -= 10000.0;
  const Grid g = parse(fixed_dem(dem));
  EXPECT_FALSE(g.georef.utm_north);
  EXPECT_DOUBLE_EQ(g.georef.y0, 10'000'000.0 - 10000.0 + 1090.0);
}

TEST(UsgsDem, VerticalDatumCodeNamesTheDatum) {
  TestDem dem = utm_dem();
  dem.vertical_datum_code = " 3";
  EXPECT_EQ(parse(fixed_dem(dem)).vertical_datum, "NAVD 88");
}

TEST(UsgsDem, ReadsMountStHelens) {
  const auto path = test::shared_dem("SainteHelens.dem");
  TERRAVOL_REQUIRE_SHARED(path);
  const Grid g = read_dem(path);
  EXPECT_EQ(g.cols, 327);
  EXPECT_EQ(g.rows, 466);
  EXPECT_EQ(g.georef.crs, Crs::kUtm);
  EXPECT_EQ(g.georef.utm_zone, 10);
  EXPECT_TRUE(g.georef.utm_north);
  EXPECT_DOUBLE_EQ(g.georef.x0, 557820.0);
  EXPECT_DOUBLE_EQ(g.georef.y0, 5121960.0);
  EXPECT_DOUBLE_EQ(g.georef.dx, 30.0);
  EXPECT_DOUBLE_EQ(g.georef.dy, 30.0);
  EXPECT_EQ(count(g, Sample::kValid), 148885u);
  EXPECT_EQ(count(g, Sample::kVoid), 0u);
  EXPECT_EQ(count(g, Sample::kOutside), 466u * 327u - 148885u);
  const auto r = height_range(g);
  EXPECT_EQ(r.min, 682.0f);
  EXPECT_EQ(r.max, 2543.0f);
  // The first profile holds 22 samples from northing 5121240 up (rows 24 down to 3).
  EXPECT_EQ(g.mask[g.index(2, 0)], Sample::kOutside);
  EXPECT_EQ(g.heights[g.index(24, 0)], 909.0f);
  EXPECT_EQ(g.heights[g.index(3, 0)], 888.0f);
  EXPECT_EQ(g.vertical_datum, "unknown (USGS DEM, mean sea level)");
  // The 1980 file leaves the horizontal datum blank: said in a note, coordinates not shifted.
  ASSERT_EQ(g.notes.size(), 1u);
  EXPECT_NE(g.notes[0].find("horizontal datum not given"), std::string::npos);
}

std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void expect_truncations_handled(const std::string& text, std::size_t step) {
  test::expect_prefixes_handled([](const std::string& t) { return parse(t); }, text, step, "t.dem");
}

TEST(UsgsDem, EveryTruncationOfSyntheticFilesFailsCleanlyOrParses) {
  expect_truncations_handled(fixed_dem(utm_dem()), 1);
  expect_truncations_handled(newline_dem(utm_dem()), 1);
  const std::string lines = newline_dem(utm_dem());
  EXPECT_EQ(error_of(lines.substr(0, lines.find('\n') + 1)),
            "t.dem: truncated after the Type A header, before profile 1 of 3");
}

TEST(UsgsDem, TruncatedMountStHelensNamesTheProfile) {
  const auto path = test::shared_dem("SainteHelens.dem");
  TERRAVOL_REQUIRE_SHARED(path);
  const std::string text = read_file(path);
  EXPECT_EQ(error_of(text.substr(0, 1024 * 6 + 500)),
            "t.dem: truncated in profile 4 of 327 (elevation 230 of 340)");
  EXPECT_EQ(error_of(text.substr(0, 1024)), "t.dem: truncated in profile 1 of 327 (row number)");
  EXPECT_EQ(error_of(text.substr(0, 500)),
            "t.dem: truncated in the Type A header (500 bytes, its fields need 864)");
  expect_truncations_handled(text, 4099);
}

TEST(UsgsDem, HugeProfileCountFailsAtOnce) {
  std::string text = fixed_dem(utm_dem());
  text.replace(858, 6, "999999");
  EXPECT_EQ(error_of(text), "t.dem: truncated in profile 4 of 999999 (row number)");
  text.replace(858, 6, "    -5");
  EXPECT_EQ(error_of(text), "t.dem: number of profiles -5 (bytes 859-864) is not 1..1048576");
}

TEST(UsgsDem, HugeProfileLengthFailsAtOnce) {
  std::string text = fixed_dem(utm_dem());
  text.replace(1024 + 12, 6, "999999");
  EXPECT_EQ(error_of(text), "t.dem: profile 1 of 3: elevation 4 of 999999 at byte 1187 is blank");
  std::string lines = newline_dem(utm_dem());
  const auto m_at = lines.find("     1     1     3     1") + 12;
  lines.replace(m_at, 6, " 99999");
  EXPECT_EQ(error_of(lines),
            "t.dem: profile 1 of 3: elevation 8 of 99999 at byte 1085 is not a number: "
            "'5.000300000000000D'");
  text.replace(1024 + 12, 6, "     0");
  EXPECT_EQ(error_of(text),
            "t.dem: profile 1 of 3 claims 0 x 1 elevations (expected m x 1, m in 1..1048576)");
}

TEST(UsgsDem, FarApartProfilesAreRejectedBeforeAllocating) {
  TestDem dem = utm_dem();
  dem.profiles[2].y = 1.0e9;
  EXPECT_NE(error_of(fixed_dem(dem)).find("more than 1048576 rows"), std::string::npos);
  dem.profiles[2].y = 1030.0 + 30.0 * 1000;
  EXPECT_EQ(error_of(fixed_dem(dem)),
            "t.dem: profiles span 1004 rows x 3 columns, far more than their 10 elevations");
}

TEST(UsgsDem, MalformedHeadersAreRejectedWithTheField) {
  std::string text = fixed_dem(utm_dem());
  text.replace(156, 6, "    x1");
  EXPECT_EQ(
      error_of(text),
      "t.dem: Type A planimetric reference system code (bytes 157-162) is not an integer: 'x1'");
  text.replace(156, 6, "     2");
  EXPECT_NE(error_of(text).find("State Plane"), std::string::npos);
  text.replace(156, 6, "     1");
  text.replace(162, 6, "    61");
  EXPECT_EQ(error_of(text), "t.dem: UTM zone 61 (bytes 163-168) is not 1..60");
  text.replace(162, 6, "    10");
  text.replace(534, 6, "     3");
  EXPECT_EQ(error_of(text),
            "t.dem: elevation units code 3 (bytes 535-540) is neither 1 (feet) nor 2 (metres)");
  text.replace(534, 6, "     2");
  text.replace(816, 12, "-0.30000E+02");
  EXPECT_NE(error_of(text).find("is not positive"), std::string::npos);
}

TEST(UsgsDem, MalformedProfilesAreRejected) {
  TestDem dem = utm_dem();
  dem.profiles[1].x += 7.0;
  EXPECT_EQ(
      error_of(fixed_dem(dem)),
      "t.dem: profile 2 of 3 is at x 500037, not 500030 (profiles must be x resolution apart)");
  dem = utm_dem();
  dem.profiles[1].y += 10.0;
  EXPECT_NE(error_of(fixed_dem(dem)).find("off the y resolution grid"), std::string::npos);
  std::string text = fixed_dem(utm_dem());
  text.replace(2048 + 6, 6, "     7");
  EXPECT_EQ(error_of(text), "t.dem: profile 2 of 3 has column number 7");
  text = fixed_dem(utm_dem());
  text.replace(1024 + 144 + 6, 6, "  1x1 ");
  EXPECT_EQ(error_of(text),
            "t.dem: profile 1 of 3: elevation 2 of 3 at byte 1175 is not a number: '1x1'");
}

TEST(UsgsDem, NonDemInputIsRejected) {
  EXPECT_NE(error_of(std::string(2000, 'x')).find("t.dem: Type A"), std::string::npos);
  EXPECT_EQ(error_of(""), "t.dem: truncated in the Type A header (0 bytes, its fields need 864)");
  std::string binary(3000, '\0');
  for (std::size_t i = 0; i < binary.size(); ++i) binary[i] = static_cast<char>(i * 7919 % 251);
  EXPECT_NE(error_of(binary), "");
  EXPECT_EQ(error_of(std::string(100, ' ') + "\n" + std::string(2000, ' ')),
            "t.dem: Type A header ends with a line break at byte 101, before its last field (bytes "
            "853-864)");
}

}  // namespace
}  // namespace terravol::io
