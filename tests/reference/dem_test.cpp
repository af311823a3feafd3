// The reference's own DEM reader: exact tiny cases on written tiles, and every sample of the real
// tiles against io/'s readers (a separate implementation, the renderer's).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <fstream>
#include <vector>

#include "io/dem_file.h"
#include "reference/dem.h"
#include "shared_data.h"
#include "temp_dir.h"

namespace terravol::reference {
namespace {

namespace fs = std::filesystem;

const Box kWorld{-90, 90, -180, 180};

// An SRTM3 tile whose sample (row r from the north, column c) is f(r, c).
template <class F>
void write_hgt(const fs::path& path, F f) {
  std::vector<char> bytes(2u * 1201 * 1201);
  for (int r = 0; r < 1201; ++r)
    for (int c = 0; c < 1201; ++c) {
      const auto v = static_cast<std::uint16_t>(static_cast<std::int16_t>(f(r, c)));
      bytes[2 * (static_cast<std::size_t>(r) * 1201 + c)] = static_cast<char>(v >> 8);
      bytes[2 * (static_cast<std::size_t>(r) * 1201 + c) + 1] = static_cast<char>(v & 0xff);
    }
  std::ofstream(path, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

TEST(Dem, SrtmSamplesArePointsFromTheNorthWestCorner) {
  test::TempDir dir;
  write_hgt(dir.path() / "N10E020.hgt", [](int r, int c) { return r - 2 * c; });
  const Dem d = Dem::read({dir.path() / "N10E020.hgt"}, kWorld);
  ASSERT_EQ(d.rows(), 1201);
  EXPECT_DOUBLE_EQ(d.south(), 10.0);
  EXPECT_DOUBLE_EQ(d.west(), 20.0);
  EXPECT_DOUBLE_EQ(d.height(11.0, 20.0), 0.0);             // the file's first sample: north-west
  EXPECT_DOUBLE_EQ(d.height(10.0, 20.0), 1200.0);          // its last row
  EXPECT_DOUBLE_EQ(d.height(11.0, 21.0), -2400.0);         // the north-east corner
  EXPECT_NEAR(d.height(11.0 - 0.5 / 1200, 20.0 + 1.5 / 1200), 0.5 - 3.0, 1e-9);  // bilinear (linear data)
}

TEST(Dem, VoidsAndPointsOutsideThrowRatherThanGuess) {
  test::TempDir dir;
  write_hgt(dir.path() / "N10E020.hgt", [](int r, int c) { return r == 600 && c == 600 ? -32768 : 5; });
  const Dem d = Dem::read({dir.path()}, kWorld);  // a folder
  EXPECT_TRUE(std::isnan(d.sample(600, 600)));
  EXPECT_DOUBLE_EQ(d.height(10.2, 20.2), 5.0);
  EXPECT_THROW(d.height(10.5, 20.5), std::runtime_error);  // its stencil holds the void
  EXPECT_THROW(d.height(9.99, 20.5), std::runtime_error);
  EXPECT_THROW(d.height(10.5, 21.01), std::runtime_error);
}

TEST(Dem, NeighbouringSrtmTilesShareTheirEdge) {
  test::TempDir dir;
  write_hgt(dir.path() / "N10E020.hgt", [](int, int c) { return c; });
  write_hgt(dir.path() / "N10E021.hgt", [](int, int c) { return 1200 + c; });
  const Dem d = Dem::read({dir.path()}, kWorld);
  EXPECT_EQ(d.cols(), 2401);
  EXPECT_DOUBLE_EQ(d.height(10.5, 21.0), 1200.0);
  EXPECT_NEAR(d.height(10.5, 21.5), 1800.0, 1e-9);
}

TEST(Dem, ReadsOnlyTheTilesNearTheBox) {
  test::TempDir dir;
  write_hgt(dir.path() / "N10E020.hgt", [](int, int) { return 1; });
  std::ofstream(dir.path() / "N30E020.hgt") << "not a tile";  // far away: never opened
  const Dem d = Dem::read({dir.path()}, {10.2, 10.4, 20.2, 20.4});
  EXPECT_EQ(d.rows(), 1201);
  EXPECT_THROW(Dem::read({dir.path()}, {30.2, 30.4, 20.2, 20.4}), std::runtime_error);  // the bad one
  EXPECT_THROW(Dem::read({dir.path() / "N10E020.hgt"}, {50, 51, 0, 1}), std::runtime_error);  // none
}

TEST(Dem, BadTilesThrowNamingTheFile) {
  test::TempDir dir;
  std::ofstream(dir.path() / "N10E020.hgt") << "short";
  try {
    Dem::read({dir.path() / "N10E020.hgt"}, kWorld);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("N10E020.hgt"), std::string::npos) << e.what();
  }
  std::ofstream(dir.path() / "10_11_20_21.sdf") << "21\n10\n20\n11\n1\n2\n";  // too few heights
  EXPECT_THROW(Dem::read({dir.path() / "10_11_20_21.sdf"}, kWorld), std::runtime_error);
  std::ofstream(dir.path() / "12_13_20_21.sdf") << "22\n12\n21\n13\n";  // header unlike the name
  EXPECT_THROW(Dem::read({dir.path() / "12_13_20_21.sdf"}, kWorld), std::runtime_error);
  std::ofstream(dir.path() / "heights.txt") << "1";
  EXPECT_THROW(Dem::read({dir.path() / "heights.txt"}, kWorld), std::runtime_error);
}

TEST(Dem, TheBundledTileAgreesWithIoSampleForSample) {
  const fs::path tile = fs::path(TERRAVOL_SOURCE_DIR) / "data" / "dem" / "N45E006.hgt";
  const Dem d = Dem::read({tile}, kWorld);
  const io::Grid g = io::read_dem(tile);
  ASSERT_EQ(d.rows(), g.rows);
  ASSERT_EQ(d.cols(), g.cols);
  for (int r = 0; r < g.rows; ++r)
    for (int c = 0; c < g.cols; ++c) {
      const float io_height = g.mask[g.index(r, c)] == io::Sample::kValid ? g.heights[g.index(r, c)] : std::nanf("");
      const float mine = d.sample(d.rows() - 1 - r, c);
      ASSERT_TRUE(mine == io_height || (std::isnan(mine) && std::isnan(io_height))) << r << " " << c;
    }
  EXPECT_DOUBLE_EQ(d.south(), g.georef.y0 - (g.rows - 1) * g.georef.dy);
  EXPECT_DOUBLE_EQ(d.west(), g.georef.x0);
}

TEST(Dem, AUtahSdfTileAgreesWithIoSampleForSample) {
  // One tile (lat 40..41, west longitude 111..112): the box selects it alone.
  const fs::path tile = test::shared_dem("utah_sdf") / "40_41_111_112.sdf.bz2";
  TERRAVOL_REQUIRE_SHARED(tile);
  const Dem d = Dem::read({tile.parent_path()}, {40.3, 40.7, -111.7, -111.3});
  const io::Grid g = io::read_dem(tile);
  ASSERT_EQ(d.rows(), g.rows);
  ASSERT_EQ(d.cols(), g.cols);
  EXPECT_NEAR(d.west(), g.georef.x0, 1e-9);
  EXPECT_NEAR(d.south(), g.georef.y0 - (g.rows - 1) * g.georef.dy, 1e-9);
  EXPECT_NEAR(d.spacing(), g.georef.dx, 1e-12);
  for (int r = 0; r < g.rows; ++r)
    for (int c = 0; c < g.cols; ++c) {
      const std::size_t k = g.index(r, c);
      ASSERT_EQ(g.mask[k], io::Sample::kValid);
      ASSERT_EQ(d.sample(d.rows() - 1 - r, c), g.heights[k]) << r << " " << c;
    }
}

}  // namespace
}  // namespace terravol::reference
