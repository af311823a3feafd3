#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <functional>
#include <iterator>
#include <string>
#include <vector>

#include "io/dem_file.h"
#include "io/error.h"
#include "io/readers.h"
#include "shared_data.h"

namespace terravol::io {
namespace {

// Signed-magnitude 16-bit encoding of a DTED height.
std::uint16_t signed_magnitude(int v) {
  return static_cast<std::uint16_t>(v < 0 ? 0x8000 | -v : v);
}

// What a synthetic DTED file holds. Defaults: a 4-column, 5-row level-0-like tile at 10 N 20 E.
struct DtedSpec {
  std::string lon_origin = "0200000E";
  std::string lat_origin = "0100000N";
  int lon_interval = 300;  // tenths of arc-seconds
  int lat_interval = 300;
  int cols = 4;
  int rows = 5;
  std::string vertical_datum = "E96";
  std::string horizontal_datum = "WGS84";
  // Raw 16-bit sample of column c, sample i counted from the south.
  std::function<std::uint16_t(int, int)> raw = [](int c, int i) {
    return signed_magnitude(100 * c + i);
  };
};

void put(std::string& record, std::size_t at, const std::string& text) {
  record.replace(at, text.size(), text);
}

std::string zero_padded(int v, int width) {
  std::string s = std::to_string(v);
  return std::string(static_cast<std::size_t>(width) - s.size(), '0') + s;
}

// The bytes of a DTED file: UHL, DSI, ACC, then one record per column with a correct checksum.
std::vector<std::uint8_t> make_dted(const DtedSpec& spec) {
  std::string uhl(80, ' ');
  put(uhl, 0, "UHL1");
  put(uhl, 4, spec.lon_origin);
  put(uhl, 12, spec.lat_origin);
  put(uhl, 20, zero_padded(spec.lon_interval, 4));
  put(uhl, 24, zero_padded(spec.lat_interval, 4));
  put(uhl, 28, "0005U  ");
  put(uhl, 47, zero_padded(spec.cols, 4));
  put(uhl, 51, zero_padded(spec.rows, 4));
  put(uhl, 55, "0");
  std::string dsi(648, ' ');
  put(dsi, 0, "DSIU");
  put(dsi, 59, "DTED0");
  put(dsi, 126, "PRF89020B");
  put(dsi, 141, spec.vertical_datum);
  put(dsi, 144, spec.horizontal_datum);
  std::string acc(2700, ' ');
  put(acc, 0, "ACC");
  const std::string head = uhl + dsi + acc;
  std::vector<std::uint8_t> out(head.begin(), head.end());
  for (int c = 0; c < spec.cols; ++c) {
    const auto hi = static_cast<std::uint8_t>(c >> 8), lo = static_cast<std::uint8_t>(c & 0xff);
    std::vector<std::uint8_t> rec = {0xAA, 0, hi, lo, hi, lo, 0, 0};  // block and longitude counts
    for (int i = 0; i < spec.rows; ++i) {
      const std::uint16_t v = spec.raw(c, i);
      rec.push_back(static_cast<std::uint8_t>(v >> 8));
      rec.push_back(static_cast<std::uint8_t>(v & 0xff));
    }
    std::uint32_t sum = 0;
    for (const std::uint8_t b : rec) sum += b;
    for (int shift = 24; shift >= 0; shift -= 8)
      rec.push_back(static_cast<std::uint8_t>(sum >> shift));
    out.insert(out.end(), rec.begin(), rec.end());
  }
  return out;
}

constexpr std::size_t kHeaderBytes = 80 + 648 + 2700;

std::size_t record_size(const DtedSpec& spec) {
  return 8 + 2 * static_cast<std::size_t>(spec.rows) + 4;
}

// The FormatError message parse_dted gives, or "no error".
std::string error_of(const std::vector<std::uint8_t>& bytes) {
  try {
    parse_dted(bytes, "x.dt1");
  } catch (const FormatError& e) {
    return e.what();
  }
  return "no error";
}

TEST(Dted, ColumnsFromSouthToNorthBecomeRowsFromNorth) {
  const DtedSpec spec;
  const Grid g = parse_dted(make_dted(spec), "x.dt0");
  EXPECT_EQ(g.format, "dted");
  ASSERT_EQ(g.rows, 5);
  ASSERT_EQ(g.cols, 4);
  for (int r = 0; r < g.rows; ++r) {
    for (int c = 0; c < g.cols; ++c) {
      EXPECT_EQ(g.heights[g.index(r, c)], static_cast<float>(100 * c + (g.rows - 1 - r)))
          << "row " << r << " column " << c;
    }
  }
  EXPECT_EQ(count(g, Sample::kValid), g.size());
  EXPECT_EQ(g.checksum_errors, 0u);
  EXPECT_TRUE(g.notes.empty());
}

TEST(Dted, GeoreferenceComesFromTheUhl) {
  DtedSpec spec;
  spec.lon_origin = "1160000W";
  spec.lat_origin = "0333000S";  // 33 30' S
  const Grid g = parse_dted(make_dted(spec), "x.dt0");
  EXPECT_EQ(g.georef.crs, Crs::kGeographic);
  EXPECT_DOUBLE_EQ(g.georef.x0, -116.0);
  EXPECT_DOUBLE_EQ(g.georef.dx, 30.0 / 3600.0);
  EXPECT_DOUBLE_EQ(g.georef.dy, 30.0 / 3600.0);
  EXPECT_DOUBLE_EQ(g.georef.y0, -33.5 + 4 * 30.0 / 3600.0);
}

TEST(Dted, HighLatitudeTileTakesItsWiderLongitudeSpacingFromTheUhl) {
  // 72 N lies in the 70..75 degree zone: the longitude interval is three times the latitude one.
  DtedSpec spec;
  spec.lon_origin = "0300000E";
  spec.lat_origin = "0720000N";
  spec.lat_interval = 300;
  spec.lon_interval = 900;
  spec.rows = 121;
  spec.cols = 41;
  const Grid g = parse_dted(make_dted(spec), "x.dt0");
  ASSERT_EQ(g.rows, 121);
  ASSERT_EQ(g.cols, 41);
  EXPECT_DOUBLE_EQ(g.georef.dx, 0.025);
  EXPECT_DOUBLE_EQ(g.georef.dy, 1.0 / 120);
  EXPECT_DOUBLE_EQ(g.georef.x0, 30.0);
  EXPECT_DOUBLE_EQ(g.georef.y0, 73.0);
  EXPECT_EQ(g.heights[g.index(0, 40)], 100.0f * 40 + 120);  // north-east corner
  EXPECT_EQ(g.heights[g.index(120, 0)], 0.0f);              // south-west corner
  EXPECT_EQ(g.heights[g.index(60, 7)], 100.0f * 7 + 60);
}

TEST(Dted, ChecksumFailuresAreCountedAndDataKept) {
  const DtedSpec spec;
  auto bytes = make_dted(spec);
  bytes[kHeaderBytes + 1 * record_size(spec) + record_size(spec) - 1] ^= 0x01;  // column 1
  bytes[kHeaderBytes + 3 * record_size(spec) + 8] = 0x00;  // column 3, sample 0: data changed
  const Grid g = parse_dted(bytes, "x.dt0");
  EXPECT_EQ(g.checksum_errors, 2u);
  EXPECT_EQ(g.heights[g.index(4, 1)], 100.0f);
  EXPECT_EQ(g.heights[g.index(3, 1)], 101.0f);
  EXPECT_EQ(g.heights[g.index(4, 3)], 300.0f - 256.0f);  // high byte 0x01 cleared, value kept
}

TEST(Dted, WrongSentinelIsAnErrorNamingTheColumn) {
  const DtedSpec spec;
  auto bytes = make_dted(spec);
  bytes[kHeaderBytes + 2 * record_size(spec)] = 0x00;
  EXPECT_EQ(error_of(bytes), "x.dt1: record 2 (column 2) sentinel is 0x00, expected 0xAA");
}

TEST(Dted, VoidIsMarkedAndNotFilled) {
  DtedSpec spec;
  spec.raw = [](int c, int i) {
    return c == 2 && i == 3 ? std::uint16_t{0xFFFF} : signed_magnitude(100 * c + i);
  };
  const Grid g = parse_dted(make_dted(spec), "x.dt0");
  EXPECT_EQ(count(g, Sample::kVoid), 1u);
  EXPECT_EQ(g.mask[g.index(1, 2)], Sample::kVoid);
  EXPECT_EQ(g.heights[g.index(1, 2)], 0.0f);
  EXPECT_EQ(g.heights[g.index(0, 2)], 204.0f);
}

TEST(Dted, NegativeHeightsAreSignedMagnitude) {
  DtedSpec spec;
  spec.raw = [](int c, int i) -> std::uint16_t {
    if (c == 0 && i == 0) return 0x8057;  // -87
    if (c == 0 && i == 1) return 0x8000;  // negative zero
    if (c == 0 && i == 2) return 0x7FFF;  // 32767
    if (c == 0 && i == 3) return 0xFFFE;  // -32766: impossible terrain, two's complement -2
    return 0;
  };
  const Grid g = parse_dted(make_dted(spec), "x.dt0");
  EXPECT_EQ(g.heights[g.index(4, 0)], -87.0f);
  EXPECT_EQ(g.heights[g.index(3, 0)], 0.0f);
  EXPECT_EQ(g.heights[g.index(2, 0)], 32767.0f);
  EXPECT_EQ(g.heights[g.index(1, 0)], -2.0f);
  EXPECT_EQ(count(g, Sample::kVoid), 0u);
  ASSERT_EQ(g.notes.size(), 1u);
  EXPECT_NE(g.notes[0].find("1 negative samples were in two's complement"), std::string::npos)
      << g.notes[0];
}

TEST(Dted, VerticalDatumComesFromTheDsi) {
  DtedSpec spec;
  EXPECT_EQ(parse_dted(make_dted(spec), "x").vertical_datum, "EGM96 geoid (DTED E96)");
  spec.vertical_datum = "MSL";
  EXPECT_EQ(parse_dted(make_dted(spec), "x").vertical_datum, "mean sea level (DTED MSL)");
  spec.vertical_datum = "   ";
  EXPECT_EQ(parse_dted(make_dted(spec), "x").vertical_datum, "unknown (DTED DSI names none)");
}

TEST(Dted, HorizontalDatumOtherThanWgs84IsNoted) {
  DtedSpec spec;
  spec.horizontal_datum = "WGS72";
  const Grid g = parse_dted(make_dted(spec), "x");
  ASSERT_EQ(g.notes.size(), 1u);
  EXPECT_EQ(g.notes[0], "DTED horizontal datum \"WGS72\" read as WGS84");
}

TEST(Dted, TapeLabelsBeforeTheUhlAreSkipped) {
  const DtedSpec spec;
  const auto plain = make_dted(spec);
  std::string labels = "VOL1" + std::string(76, ' ') + "HDR1" + std::string(76, ' ');
  std::vector<std::uint8_t> bytes(labels.begin(), labels.end());
  bytes.insert(bytes.end(), plain.begin(), plain.end());
  const Grid g = parse_dted(bytes, "x");
  EXPECT_EQ(g.heights, parse_dted(plain, "x").heights);
}

TEST(Dted, TrailingBytesAreIgnoredWithANote) {
  auto bytes = make_dted(DtedSpec{});
  bytes.insert(bytes.end(), 7, 0x00);
  const Grid g = parse_dted(bytes, "x");
  ASSERT_EQ(g.notes.size(), 1u);
  EXPECT_EQ(g.notes[0], "7 bytes after the last DTED record were ignored");
}

TEST(Dted, TruncationNamesWhereItHappened) {
  const DtedSpec spec;
  const auto bytes = make_dted(spec);
  auto cut = [&](std::size_t n) {
    return error_of(std::vector<std::uint8_t>(bytes.begin(), bytes.begin() + static_cast<long>(n)));
  };
  EXPECT_EQ(cut(0), "x.dt1: truncated in the UHL header: 0 of 80 bytes");
  EXPECT_EQ(cut(50), "x.dt1: truncated in the UHL header: 50 of 80 bytes");
  EXPECT_EQ(cut(100), "x.dt1: truncated in the DSI header: 20 of 648 bytes");
  EXPECT_EQ(cut(80 + 648 + 1), "x.dt1: truncated in the ACC header: 1 of 2700 bytes");
  EXPECT_EQ(cut(kHeaderBytes), "x.dt1: truncated in column 0 of 4");
  EXPECT_EQ(cut(kHeaderBytes + 2 * record_size(spec) + 5), "x.dt1: truncated in column 2 of 4");
  EXPECT_EQ(cut(bytes.size() - 1), "x.dt1: truncated in column 3 of 4");
}

TEST(Dted, EveryTruncationIsAOneLineFormatError) {
  DtedSpec spec;
  spec.cols = 3;
  spec.rows = 3;
  const auto bytes = make_dted(spec);
  for (std::size_t n = 0; n < bytes.size(); ++n) {
    const std::string e =
        error_of(std::vector<std::uint8_t>(bytes.begin(), bytes.begin() + static_cast<long>(n)));
    ASSERT_EQ(e.rfind("x.dt1: ", 0), 0u) << "length " << n << ": " << e;
    ASSERT_EQ(e.find('\n'), std::string::npos) << e;
  }
}

TEST(Dted, MalformedUhlFieldsAreRejected) {
  DtedSpec spec;
  spec.lon_origin = "1160000X";
  EXPECT_EQ(error_of(make_dted(spec)),
            "x.dt1: UHL longitude of origin \"1160000X\" is not DDDMMSSH with H = E or W");
  spec = DtedSpec{};
  spec.lat_origin = "0336000N";  // 60 minutes
  EXPECT_NE(error_of(make_dted(spec)).find("UHL latitude of origin \"0336000N\""),
            std::string::npos);
  spec = DtedSpec{};
  spec.lon_interval = 0;
  EXPECT_NE(error_of(make_dted(spec)).find("intervals \"00000300\" are not two positive"),
            std::string::npos);
  spec = DtedSpec{};
  auto bytes = make_dted(spec);
  bytes[49] = 'x';  // number of longitude lines
  EXPECT_NE(error_of(bytes).find("UHL numbers of longitude lines and latitude points \"00x40005\""),
            std::string::npos);
  bytes = make_dted(spec);
  bytes[0] = 'G';
  EXPECT_EQ(error_of(bytes), "x.dt1: expected the DTED UHL header at byte 0, found \"GHL\"");
  bytes = make_dted(spec);
  bytes[80] = 'X';
  EXPECT_EQ(error_of(bytes), "x.dt1: expected the DTED DSI header at byte 80, found \"XSI\"");
}

TEST(Dted, TileReachingPastThePoleIsRejected) {
  DtedSpec spec;
  spec.lat_origin = "0890000N";
  spec.rows = 241;  // two degrees at 30"
  spec.cols = 2;
  EXPECT_NE(error_of(make_dted(spec)).find("beyond the pole or the antimeridian"),
            std::string::npos);
}

TEST(Dted, HeaderCountsLargerThanTheFileAreTruncationNotAllocation) {
  DtedSpec spec;
  auto bytes = make_dted(spec);
  std::string big = "9999";
  std::copy(big.begin(), big.end(), bytes.begin() + 47);
  std::copy(big.begin(), big.end(), bytes.begin() + 51);
  EXPECT_EQ(error_of(bytes), "x.dt1: truncated in column 0 of 9999");
}

TEST(Dted, ReadsTheSaltonSeaTile) {
  const auto path = test::shared_dem("n33_w116_3arc_v2.dt1");
  TERRAVOL_REQUIRE_SHARED(path);
  const Grid g = read_dem(path);
  EXPECT_EQ(g.format, "dted");
  EXPECT_EQ(g.rows, 1201);
  EXPECT_EQ(g.cols, 1201);
  EXPECT_DOUBLE_EQ(g.georef.x0, -116.0);
  EXPECT_DOUBLE_EQ(g.georef.y0, 34.0);
  EXPECT_DOUBLE_EQ(g.georef.dx, 1.0 / 1200);
  EXPECT_DOUBLE_EQ(g.georef.dy, 1.0 / 1200);
  EXPECT_DOUBLE_EQ(g.georef.x0 + (g.cols - 1) * g.georef.dx, -115.0);
  EXPECT_DOUBLE_EQ(g.georef.y0 - (g.rows - 1) * g.georef.dy, 33.0);
  const auto r = height_range(g);
  EXPECT_EQ(r.min, -87.0f);
  EXPECT_EQ(r.max, 1619.0f);
  EXPECT_EQ(count(g, Sample::kVoid), 0u);
  EXPECT_EQ(g.checksum_errors, 0u);
  EXPECT_EQ(g.vertical_datum, "EGM96 geoid (DTED E96)");
  EXPECT_TRUE(g.notes.empty());
}

TEST(Dted, RealTileCutAnywhereIsAFormatError) {
  const auto path = test::shared_dem("n33_w116_3arc_v2.dt1");
  TERRAVOL_REQUIRE_SHARED(path);
  std::ifstream in(path, std::ios::binary);
  const std::vector<std::uint8_t> bytes{std::istreambuf_iterator<char>(in),
                                        std::istreambuf_iterator<char>()};
  ASSERT_EQ(bytes.size(), 2902642u);
  std::vector<std::size_t> lengths;
  for (std::size_t n = 0; n <= kHeaderBytes + 20; ++n) lengths.push_back(n);
  for (std::size_t n = kHeaderBytes + 21; n < bytes.size(); n += 9973) lengths.push_back(n);
  for (std::size_t n = bytes.size() - 20; n < bytes.size(); ++n) lengths.push_back(n);
  for (const std::size_t n : lengths) {
    const std::string e =
        error_of(std::vector<std::uint8_t>(bytes.begin(), bytes.begin() + static_cast<long>(n)));
    ASSERT_EQ(e.rfind("x.dt1: truncated in ", 0), 0u) << "length " << n << ": " << e;
  }
  EXPECT_EQ(error_of(std::vector<std::uint8_t>(bytes.begin(), bytes.end() - 1)),
            "x.dt1: truncated in column 1200 of 1201");
}

}  // namespace
}  // namespace terravol::io
