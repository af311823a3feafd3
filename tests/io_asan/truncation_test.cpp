// Hostile input under AddressSanitizer and UBSan (this executable links terravol_io_asan):
// every reader's real file cut at every length within its headers and at spread lengths past
// them, and with trailing bytes, must parse or throw FormatError with a one-line message;
// never crash, read out of bounds, hang or throw anything else.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

#include "compress.h"
#include "io/dem_file.h"
#include "io/error.h"
#include "parse_check.h"
#include "shared_data.h"

namespace terravol::io {
namespace {

struct Case {
  const char* file;
  std::size_t every_length_up_to;  // covers the headers and the first records
  std::size_t spread_lengths;      // further lengths, evenly spread over the rest
};

void PrintTo(const Case& c, std::ostream* os) { *os << c.file; }

// Parses content[0, n) and checks the outcome.
void expect_parse_or_clean_error(Format format, const std::vector<std::uint8_t>& content, std::size_t n,
                                 const std::string& name) {
  const std::vector<std::uint8_t> cut(content.begin(), content.begin() + static_cast<std::ptrdiff_t>(n));
  test::expect_grid_or_one_line_error([&] { return parse_dem(format, cut, "cut", name); }, "cut",
                                      "length " + std::to_string(n));
}

class Truncation : public ::testing::TestWithParam<Case> {};

TEST_P(Truncation, EveryCutParsesOrFailsWithOneLine) {
  const Case c = GetParam();
  const auto path = test::shared_dem(c.file);
  TERRAVOL_REQUIRE_SHARED(path);
  const auto format = format_from_name(path);
  ASSERT_TRUE(format);
  const std::vector<std::uint8_t> content = read_content(path);
  const std::string name = path.filename().string();
  const std::size_t dense = std::min(c.every_length_up_to, content.size());
  for (std::size_t n = 0; n <= dense; ++n) expect_parse_or_clean_error(*format, content, n, name);
  for (std::size_t k = 1; k <= c.spread_lengths; ++k) {
    const std::size_t n = dense + (content.size() - dense) * k / (c.spread_lengths + 1);
    expect_parse_or_clean_error(*format, content, n, name);
  }
  // The whole file, and the whole file with trailing bytes.
  expect_parse_or_clean_error(*format, content, content.size(), name);
  std::vector<std::uint8_t> longer = content;
  longer.insert(longer.end(), {'7', ' ', '\n', 0xff, 0x00, 0x12});
  expect_parse_or_clean_error(*format, longer, longer.size(), name);
}

INSTANTIATE_TEST_SUITE_P(
    RealFiles, Truncation,
    ::testing::Values(Case{"N44W072.hgt", 4096, 16}, Case{"n33_w116_3arc_v2.dt1", 3428 + 2 * 2414 + 8, 24},
                      Case{"SainteHelens.dem", 2 * 1024 + 64, 24}, Case{"front_range_srtmgl3.asc", 4096, 16},
                      Case{"olinda_dem_utm25s.tif", 50000, 0}, Case{"utah_sdf/40_41_111_112.sdf.bz2", 2048, 8}),
    [](const auto& param_info) {
      std::string name = param_info.param.file;
      for (char& ch : name)
        if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
      return name;
    });

// A real file compressed each way, then cut at every length up to 2 KiB and at spread lengths
// past that, and with bytes flipped: decompressing and parsing gives the grid or one line.
class CompressedTruncation : public ::testing::TestWithParam<const char*> {};

TEST_P(CompressedTruncation, EveryCutAndFlipDecompressesAndParsesOrFailsWithOneLine) {
  const std::string ext = GetParam();
  const auto path = test::shared_dem("olinda_dem_utm25s.tif");
  TERRAVOL_REQUIRE_SHARED(path);
  const std::string name = path.filename().string();
  const std::vector<std::uint8_t> packed = test::compress_as(ext, read_content(path), name);
  auto check = [&](const std::vector<std::uint8_t>& bytes, const std::string& context) {
    test::expect_grid_or_one_line_error(
        [&] { return parse_dem(Format::kGeoTiff, decompress_content(bytes, "cut", name + ext), "cut", name); }, "cut",
        context);
  };
  const std::size_t dense = std::min<std::size_t>(2048, packed.size());
  for (std::size_t n = 0; n <= dense; ++n) check({packed.begin(), packed.begin() + static_cast<std::ptrdiff_t>(n)}, "length " + std::to_string(n));
  for (std::size_t k = 1; k <= 64; ++k) {
    const std::size_t n = dense + (packed.size() - dense) * k / 65;
    check({packed.begin(), packed.begin() + static_cast<std::ptrdiff_t>(n)}, "length " + std::to_string(n));
  }
  std::mt19937 rng(17);
  std::uniform_int_distribution<std::size_t> at(0, packed.size() - 1);
  for (int trial = 0; trial < 64; ++trial) {
    std::vector<std::uint8_t> bad = packed;
    const std::size_t i = at(rng);
    bad[i] = static_cast<std::uint8_t>(bad[i] ^ (1u << (trial % 8)));
    check(bad, "byte " + std::to_string(i) + " flipped");
  }
}

INSTANTIATE_TEST_SUITE_P(EveryCompression, CompressedTruncation, ::testing::Values(".gz", ".bz2", ".xz", ".zip"),
                         [](const auto& param_info) { return std::string(param_info.param + 1); });

// Absurd header values must be refused before anything large is allocated (ASan would report
// an allocation over its limit; the readers refuse first).
TEST(HostileHeaders, AbsurdDimensionsAreRefusedWithoutAllocating) {
  const std::string asc = "ncols 1000000000\nnrows 1000000000\nxllcorner 0\nyllcorner 0\ncellsize 0.001\n1 2\n";
  EXPECT_THROW(parse_dem(Format::kEsriAscii, {reinterpret_cast<const std::uint8_t*>(asc.data()), asc.size()}, "x",
                         "x.asc"),
               FormatError);
  const std::string sdf = "112\n40\n111\n41\n1\n2\n";
  EXPECT_THROW(parse_dem(Format::kSdf, {reinterpret_cast<const std::uint8_t*>(sdf.data()), sdf.size()}, "x",
                         "x.sdf"),
               FormatError);
}

}  // namespace
}  // namespace terravol::io
