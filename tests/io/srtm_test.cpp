#include <gtest/gtest.h>

#include "io/dem_file.h"
#include "io/error.h"
#include "io/srtm_write.h"
#include "shared_data.h"

namespace terravol::io {
namespace {

TEST(SrtmName, ParsesCornerInAnyCase) {
  auto c = srtm_corner_from_name("N44W072.hgt");
  ASSERT_TRUE(c);
  EXPECT_EQ(c->south, 44);
  EXPECT_EQ(c->west, -72);
  c = srtm_corner_from_name("s46w066.hgt.gz");
  ASSERT_TRUE(c);
  EXPECT_EQ(c->south, -46);
  EXPECT_EQ(c->west, -66);
  c = srtm_corner_from_name("n00e179.hgt");
  ASSERT_TRUE(c);
  EXPECT_EQ(c->west, 179);
}

TEST(SrtmName, RejectsMalformedNames) {
  EXPECT_FALSE(srtm_corner_from_name("X44W072.hgt"));
  EXPECT_FALSE(srtm_corner_from_name("N4W072.hgt"));
  EXPECT_FALSE(srtm_corner_from_name("N44W1a2.hgt"));
  EXPECT_FALSE(srtm_corner_from_name("N95W072.hgt"));
  EXPECT_FALSE(srtm_corner_from_name("N44E180.hgt"));
}

TEST(SrtmName, RoundTripsThroughTileName) {
  for (int lat = -60; lat < 60; lat += 7) {
    for (int lon = -180; lon < 180; lon += 13) {
      const auto c = srtm_corner_from_name(srtm_tile_name(lat, lon));
      ASSERT_TRUE(c);
      EXPECT_EQ(c->south, lat);
      EXPECT_EQ(c->west, lon);
    }
  }
}

Grid ramp_tile() {
  Grid g;
  g.allocate(1201, 1201);
  for (int r = 0; r < 1201; ++r)
    for (int c = 0; c < 1201; ++c) g.heights[g.index(r, c)] = static_cast<float>(r - c);
  g.mask[g.index(5, 7)] = Sample::kVoid;
  return g;
}

TEST(Srtm, EncodedTileParsesBackWithVoidsAndGeoreference) {
  const Grid in = ramp_tile();
  const auto bytes = encode_srtm(in);
  const Grid out = parse_srtm(bytes, "mem", "S10E020.hgt");
  EXPECT_EQ(out.rows, 1201);
  EXPECT_EQ(out.cols, 1201);
  EXPECT_DOUBLE_EQ(out.georef.x0, 20.0);
  EXPECT_DOUBLE_EQ(out.georef.y0, -9.0);
  EXPECT_DOUBLE_EQ(out.georef.dx, 1.0 / 1200);
  EXPECT_EQ(out.heights[out.index(3, 1)], 2.0f);
  EXPECT_EQ(out.mask[out.index(5, 7)], Sample::kVoid);
  EXPECT_EQ(count(out, Sample::kVoid), 1u);
}

TEST(Srtm, WrongSizeIsRejectedWithTheSizeInTheMessage) {
  const std::vector<std::uint8_t> bytes(1000);
  try {
    parse_srtm(bytes, "x.hgt", "N44W072.hgt");
    FAIL() << "expected FormatError";
  } catch (const FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("x.hgt: size 1000 bytes"), std::string::npos) << e.what();
  }
}

TEST(Srtm, ReadsTheWhiteMountainsTile) {
  const auto path = test::shared_dem("N44W072.hgt");
  TERRAVOL_REQUIRE_SHARED(path);
  const Grid g = read_dem(path);
  EXPECT_EQ(g.rows, 1201);
  EXPECT_EQ(g.georef.x0, -72.0);
  EXPECT_EQ(g.georef.y0, 45.0);
  const auto r = height_range(g);
  EXPECT_EQ(r.min, 115.0f);
  EXPECT_EQ(r.max, 1908.0f);
  EXPECT_EQ(count(g, Sample::kVoid), 0u);
}

TEST(Srtm, ReadsGzippedSrtm1Tile) {
  const auto path = test::shared_dem("S46W066.hgt.gz");
  TERRAVOL_REQUIRE_SHARED(path);
  const Grid g = read_dem(path);
  EXPECT_EQ(g.rows, 3601);
  EXPECT_EQ(g.georef.y0, -45.0);
  EXPECT_EQ(g.georef.x0, -66.0);
  const auto r = height_range(g);
  EXPECT_EQ(r.min, -3.0f);
  EXPECT_EQ(r.max, 146.0f);
}

TEST(Srtm, KauaiTileCountsItsVoids) {
  const auto path = test::shared_dem("N22W160.hgt");
  TERRAVOL_REQUIRE_SHARED(path);
  const Grid g = read_dem(path);
  EXPECT_EQ(count(g, Sample::kVoid), 4279u);
  const auto r = height_range(g);
  EXPECT_EQ(r.min, -34.0f);
  EXPECT_EQ(r.max, 1579.0f);
}

}  // namespace
}  // namespace terravol::io
