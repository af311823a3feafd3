#include <gtest/gtest.h>

#include <algorithm>
#include <charconv>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <string>
#include <vector>

#include "io/compressed.h"
#include "io/dem_file.h"
#include "io/error.h"
#include "io/readers.h"
#include "io/sdf_name.h"
#include "shared_data.h"

namespace terravol::io {
namespace {

// SPLAT!'s height for latitude index x (from the south) and longitude index y (from the east).
int ramp(int x, int y) {
  return (x * 37 + y * 11) % 5000 - 100;
}

// The text of an SDF file: the header, then ippd^2 heights in SPLAT!'s order, one a line.
std::string make_sdf(const std::string& header, int ippd,
                     const std::function<int(int, int)>& height = ramp) {
  std::string s = header;
  s.reserve(s.size() + static_cast<std::size_t>(ippd) * ippd * 6);
  char buf[16];
  for (int x = 0; x < ippd; ++x) {
    for (int y = 0; y < ippd; ++y) {
      const auto end = std::to_chars(buf, buf + sizeof buf, height(x, y)).ptr;
      s.append(buf, end);
      s += '\n';
    }
  }
  return s;
}

const std::string kHeader = "112\n40\n111\n41\n";  // 40..41 N, 112..111 W

// One 3" tile with the ramp, built once.
const std::string& ramp_tile() {
  static const std::string text = make_sdf(kHeader, 1200);
  return text;
}

std::string with_header(const std::string& header) {
  return header + ramp_tile().substr(kHeader.size());
}

// The FormatError message parse_sdf gives, or "no error".
std::string error_of(std::string_view text) {
  try {
    parse_sdf(text, "x.sdf");
  } catch (const FormatError& e) {
    return e.what();
  }
  return "no error";
}

TEST(Sdf, RowsFromTheSouthEachFromTheEastBecomeRowsFromTheNorthColumnsFromTheWest) {
  const Grid g = parse_sdf(ramp_tile(), "x.sdf");
  EXPECT_EQ(g.format, "sdf");
  ASSERT_EQ(g.rows, 1200);
  ASSERT_EQ(g.cols, 1200);
  for (int r = 0; r < g.rows; ++r) {
    for (int c = 0; c < g.cols; ++c) {
      ASSERT_EQ(g.heights[g.index(r, c)], static_cast<float>(ramp(1199 - r, 1199 - c)))
          << "row " << r << " column " << c;
    }
  }
  EXPECT_EQ(count(g, Sample::kValid), g.size());
  EXPECT_NE(g.vertical_datum.find("unknown"), std::string::npos);
}

TEST(Sdf, GeoreferenceComesFromTheWestPositiveHeaderWithoutSharedEdges) {
  const Grid g = parse_sdf(ramp_tile(), "x.sdf");
  EXPECT_EQ(g.georef.crs, Crs::kGeographic);
  EXPECT_DOUBLE_EQ(g.georef.x0, -112.0);                  // column 0 at max west
  EXPECT_DOUBLE_EQ(g.georef.y0, 40.0 + 1199.0 / 1200.0);  // row 0 one sample short of 41 N
  EXPECT_DOUBLE_EQ(g.georef.dx, 1.0 / 1200);
  EXPECT_DOUBLE_EQ(g.georef.dy, 1.0 / 1200);
  EXPECT_DOUBLE_EQ(g.georef.x0 + 1199 * g.georef.dx, -111.0 - 1.0 / 1200);
  EXPECT_DOUBLE_EQ(g.georef.y0 - 1199 * g.georef.dy, 40.0);
}

TEST(Sdf, WestLongitudesWrapModulo360IntoTheEasternHemisphere) {
  struct Case {
    const char* header;
    double x0;
  };
  for (const Case& c : {Case{"0\n-34\n359\n-33\n", 0.0}, Case{"360\n-34\n359\n-33\n", 0.0},
                        Case{"359\n10\n358\n11\n", 1.0}, Case{"181\n10\n180\n11\n", 179.0},
                        Case{"180\n10\n179\n11\n", -180.0}}) {
    const Grid g = parse_sdf(with_header(c.header), "x.sdf");
    EXPECT_DOUBLE_EQ(g.georef.x0, c.x0) << c.header;
  }
  EXPECT_DOUBLE_EQ(parse_sdf(with_header("0\n-34\n359\n-33\n"), "x").georef.y0,
                   -34 + 1199.0 / 1200);
}

TEST(Sdf, InconsistentHeaderIsAOneLineError) {
  EXPECT_EQ(error_of(with_header("112\n40\n111\n42\n")),
            "x.sdf: inconsistent header: max north 42 is not min north 40 + 1");
  EXPECT_EQ(error_of(with_header("113\n40\n111\n41\n")),
            "x.sdf: inconsistent header: max west 113 is not min west 111 + 1 (modulo 360)");
  EXPECT_EQ(error_of(with_header("112\n90\n111\n91\n")),
            "x.sdf: inconsistent header: min north 90 is outside -90..89");
  EXPECT_EQ(error_of(with_header("412\n40\n411\n41\n")),
            "x.sdf: inconsistent header: west longitudes 411 and 412 are not both in 0..360");
  EXPECT_EQ(error_of(with_header("112\n40.5\n111\n41\n")),
            "x.sdf: line 2: header value min north \"40.5\" is not an integer number of degrees");
  EXPECT_EQ(error_of("112\n40\n"),
            "x.sdf: truncated in the header: 2 of 4 values (max west, min north, min west, max "
            "north)");
  EXPECT_EQ(error_of(""),
            "x.sdf: truncated in the header: 0 of 4 values (max west, min north, "
            "min west, max north)");
}

TEST(Sdf, TooFewHeightsIsTruncation) {
  const std::string& t = ramp_tile();
  const std::size_t last_line = t.rfind('\n', t.size() - 2) + 1;
  EXPECT_EQ(error_of(std::string_view(t).substr(0, last_line)),
            "x.sdf: truncated: 1439999 of 1440000 heights of a 3\" tile");
  EXPECT_EQ(error_of(kHeader + "5\n"), "x.sdf: truncated: 1 of 1440000 heights of a 3\" tile");
}

TEST(Sdf, CutLastHeightIsTruncation) {
  const std::string& t = ramp_tile();
  EXPECT_EQ(error_of(std::string_view(t).substr(0, t.size() - 1)),
            "x.sdf: truncated: the last height has no line break after it");
  EXPECT_EQ(error_of(std::string_view(t).substr(0, t.size() - 2)),
            "x.sdf: truncated: the last height has no line break after it");
}

TEST(Sdf, HeightCountOfNeitherResolutionIsRejected) {
  EXPECT_EQ(error_of(ramp_tile() + "7\n"),
            "x.sdf: holds 1440001 heights; a 3\" tile has 1440000 and a 1\" tile 12960000");
}

TEST(Sdf, BadHeightNamesItsLine) {
  std::string t = ramp_tile();
  // Height k is on line 5 + k; replace height 1000 (x = 0, y = 1000) with junk.
  std::size_t at = kHeader.size();
  for (int i = 0; i < 1000; ++i) at = t.find('\n', at) + 1;
  t.replace(at, t.find('\n', at) - at, "12a");
  EXPECT_EQ(error_of(t),
            "x.sdf: line 1005: height \"12a\" is not an integer number of metres in -32768..32767");
  t.replace(at, 3, "40000");
  EXPECT_EQ(
      error_of(t),
      "x.sdf: line 1005: height \"40000\" is not an integer number of metres in -32768..32767");
}

TEST(Sdf, Srtm32768IsMarkedVoid) {
  const std::string t =
      make_sdf(kHeader, 1200, [](int x, int y) { return x == 0 && y == 0 ? -32768 : ramp(x, y); });
  const Grid g = parse_sdf(t, "x.sdf");
  EXPECT_EQ(count(g, Sample::kVoid), 1u);
  EXPECT_EQ(g.mask[g.index(1199, 1199)], Sample::kVoid);  // south-east sample
}

TEST(Sdf, CrLfLineEndingsAreAccepted) {
  std::string t;
  for (const char c : ramp_tile()) {
    if (c == '\n') t += '\r';
    t += c;
  }
  const Grid g = parse_sdf(t, "x.sdf");
  EXPECT_EQ(g.heights, parse_sdf(ramp_tile(), "x.sdf").heights);
}

TEST(Sdf, OneArcSecondTileIsToldApartByItsCount) {
  const std::string t = make_sdf(kHeader, 3600, [](int x, int y) { return x - y; });
  const Grid g = parse_sdf(t, "x-hd.sdf");
  ASSERT_EQ(g.rows, 3600);
  ASSERT_EQ(g.cols, 3600);
  EXPECT_DOUBLE_EQ(g.georef.dx, 1.0 / 3600);
  EXPECT_DOUBLE_EQ(g.georef.y0, 40.0 + 3599.0 / 3600);
  EXPECT_DOUBLE_EQ(g.georef.x0, -112.0);
  EXPECT_EQ(g.heights[g.index(0, 0)], 0.0f);         // x = 3599, y = 3599
  EXPECT_EQ(g.heights[g.index(0, 3599)], 3599.0f);   // x = 3599, y = 0
  EXPECT_EQ(g.heights[g.index(3599, 0)], -3599.0f);  // x = 0, y = 3599
}

TEST(SdfName, ParsesUnderscoreAndColonNames) {
  for (const char* name : {"40_41_111_112.sdf.bz2", "40:41:111:112.sdf", "40_41_111_112.SDF",
                           "40:41:111:112-hd.sdf", "40:41:111:112", "dir/40_41_111_112.sdf",
                           "40_41_111_112.sdf.gz", "40_41_111_112.sdf.XZ", "40:41:111:112-hd.sdf.zip"}) {
    const auto c = sdf_corner_from_name(name);
    ASSERT_TRUE(c) << name;
    EXPECT_EQ(c->south, 40) << name;
    EXPECT_EQ(c->west, -112) << name;
  }
}

TEST(SdfName, WestLongitudesWrapAndSouthernLatitudesAreNegative) {
  auto c = sdf_corner_from_name("-34:-33:359:0.sdf");  // srtm2sdf's name for S34E000
  ASSERT_TRUE(c);
  EXPECT_EQ(c->south, -34);
  EXPECT_EQ(c->west, 0);
  c = sdf_corner_from_name("10:11:358:359.sdf");  // N10E001
  ASSERT_TRUE(c);
  EXPECT_EQ(c->west, 1);
  c = sdf_corner_from_name("10:11:179:180.sdf");  // N10W180
  ASSERT_TRUE(c);
  EXPECT_EQ(c->west, -180);
}

TEST(SdfName, RejectsMalformedNames) {
  for (const char* name :
       {"", ".sdf", "40_41_111.sdf", "40_41_111_113.sdf", "40_42_111_112.sdf", "40_41:111_112.sdf",
        "40_41_111_112.hgt", "40_41_111_112.bz2", "40_41_111_112.gz", "40_41_111_112.sdf.tar",
        "40_41_111_112.sdf.gz.gz", "40_41_111_1120.sdf", "90_91_111_112.sdf",
        "40_41_111_112x.sdf", "N40W112.sdf", "40_41_-1_0.sdf"}) {
    EXPECT_FALSE(sdf_corner_from_name(name)) << name;
  }
}

TEST(Sdf, ReadsAUtahTileWhereItsNameSays) {
  const auto path = test::shared_dem("utah_sdf/40_41_111_112.sdf.bz2");
  TERRAVOL_REQUIRE_SHARED(path);
  const Grid g = read_dem(path);
  EXPECT_EQ(g.rows, 1200);
  EXPECT_EQ(g.cols, 1200);
  EXPECT_DOUBLE_EQ(g.georef.x0, -112.0);
  EXPECT_DOUBLE_EQ(g.georef.y0, 40.0 + 1199.0 / 1200);
  EXPECT_DOUBLE_EQ(g.georef.dx, 1.0 / 1200);
  const auto corner = sdf_corner_from_name(path.filename().string());
  ASSERT_TRUE(corner);
  EXPECT_DOUBLE_EQ(g.georef.x0, corner->west);
  EXPECT_DOUBLE_EQ(g.georef.y0 - (g.rows - 1) * g.georef.dy, corner->south);
  EXPECT_EQ(count(g, Sample::kVoid), 0u);
}

TEST(Sdf, SixUtahTilesSpan1242To4111Metres) {
  const auto dir = test::shared_dem("utah_sdf");
  TERRAVOL_REQUIRE_SHARED(dir);
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) files.push_back(entry.path());
  ASSERT_EQ(files.size(), 6u);
  float lo = 1e9f, hi = -1e9f;
  for (const auto& f : files) {
    const Grid g = read_dem(f);
    const auto corner = sdf_corner_from_name(f.filename().string());
    ASSERT_TRUE(corner) << f;
    EXPECT_DOUBLE_EQ(g.georef.x0, corner->west) << f;
    EXPECT_DOUBLE_EQ(g.georef.y0, corner->south + 1199.0 / 1200) << f;
    const auto r = height_range(g);
    ASSERT_TRUE(r.any);
    lo = std::min(lo, r.min);
    hi = std::max(hi, r.max);
  }
  EXPECT_EQ(lo, 1242.0f);
  EXPECT_EQ(hi, 4111.0f);
}

TEST(Sdf, RealTileCutAnywhereIsAFormatError) {
  const auto path = test::shared_dem("utah_sdf/41_42_112_113.sdf.bz2");
  TERRAVOL_REQUIRE_SHARED(path);
  std::ifstream in(path, std::ios::binary);
  const std::vector<std::uint8_t> packed{std::istreambuf_iterator<char>(in),
                                         std::istreambuf_iterator<char>()};
  const auto bytes = bunzip2(packed, path.string());
  const std::string_view text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  std::vector<std::size_t> lengths;
  for (std::size_t n = 0; n < 40; ++n) lengths.push_back(n);
  for (std::size_t n = 40; n < text.size(); n += text.size() / 37) lengths.push_back(n);
  for (std::size_t n = text.size() - 8; n < text.size(); ++n) lengths.push_back(n);
  for (const std::size_t n : lengths) {
    const std::string e = error_of(text.substr(0, n));
    ASSERT_EQ(e.rfind("x.sdf: ", 0), 0u) << "length " << n << ": " << e;
    ASSERT_EQ(e.find('\n'), std::string::npos) << e;
  }
  EXPECT_EQ(error_of(text), "no error");
}

}  // namespace
}  // namespace terravol::io
