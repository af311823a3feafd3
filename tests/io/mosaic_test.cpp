#include "io/mosaic.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <random>
#include <thread>
#include <vector>

#include "compress.h"
#include "io/error.h"
#include "io/srtm_write.h"
#include "shared_data.h"
#include "temp_dir.h"

namespace terravol::io {
namespace {

// Height of a global function at a lattice point of 3" spacing: integer metres so that
// it survives the int16 round trip exactly.
float global_height(double lat, double lon) {
  return static_cast<float>(std::lround(1000.0 + 400.0 * std::sin(lat * 3.0) + 300.0 * std::cos(lon * 2.0)));
}

// An SRTM3 tile of global_height, compressed as `extension` says (".gz", ...; "" for none).
void write_tile(const std::filesystem::path& dir, int south, int west, float edge_offset = 0.0f,
                const std::string& extension = "") {
  Grid g;
  g.allocate(1201, 1201);
  for (int r = 0; r < 1201; ++r)
    for (int c = 0; c < 1201; ++c) {
      g.heights[g.index(r, c)] = global_height(south + 1.0 - r / 1200.0, west + c / 1200.0);
      if (c == 0) g.heights[g.index(r, c)] += edge_offset;
    }
  const std::string name = srtm_tile_name(south, west) + ".hgt";
  const auto bytes = encode_srtm(g);
  test::write_file_bytes(dir / (name + extension),
                         extension.empty() ? bytes : test::compress_as(extension, bytes, name));
}

// A SPLAT! SDF tile of global_height at 3" (1200 x 1200, no shared edges), written in SPLAT!'s
// order as its documentation gives it: the header (max west, min north, min west, max north,
// longitudes west-positive), then rows from the south, each from the east.
void write_sdf_tile(const std::filesystem::path& path, int south, int west, const std::string& extension) {
  std::string text = std::to_string(-west) + "\n" + std::to_string(south) + "\n" + std::to_string(-west - 1) +
                     "\n" + std::to_string(south + 1) + "\n";
  text.reserve(8'000'000);
  for (int x = 0; x < 1200; ++x)
    for (int y = 0; y < 1200; ++y) {
      const double lat = south + x / 1200.0, lon = west + 1.0 - (y + 1) / 1200.0;
      text += std::to_string(static_cast<long>(global_height(lat, lon))) + "\n";
    }
  const test::ByteVector bytes(text.begin(), text.end());
  test::write_file_bytes(path.string() + extension, test::compress_as(extension, bytes, path.filename().string()));
}

TEST(Mosaic, TwoByTwoTilesShareTheirEdgesAndFormOneLattice) {
  test::TempDir dir;
  for (int s : {44, 45})
    for (int w : {-72, -71}) write_tile(dir.path(), s, w);
  const Mosaic m = Mosaic::open({dir.path()});
  EXPECT_EQ(m.rows(), 2401);
  EXPECT_EQ(m.cols(), 2401);
  EXPECT_EQ(m.georef().x0, -72.0);
  EXPECT_EQ(m.georef().y0, 46.0);
  EXPECT_TRUE(m.gaps().empty());
  EXPECT_EQ(m.loads(), 0u) << "SRTM tiles are placed from their names without reading them";

  const Grid w = m.read_window(1100, 1150, 200, 100);  // across all four tiles
  EXPECT_EQ(m.loads(), 4u);
  for (int r = 0; r < w.rows; ++r)
    for (int c = 0; c < w.cols; ++c) {
      ASSERT_EQ(w.mask[w.index(r, c)], Sample::kValid);
      ASSERT_EQ(w.heights[w.index(r, c)], global_height(46.0 - (1100 + r) / 1200.0, -72.0 + (1150 + c) / 1200.0));
    }
}

TEST(Mosaic, WindowInsideOneTileLoadsOnlyThatTile) {
  test::TempDir dir;
  for (int s : {44, 45})
    for (int w : {-72, -71}) write_tile(dir.path(), s, w);
  const Mosaic m = Mosaic::open({dir.path()}, {}, 1);
  m.read_window(10, 10, 64, 64);
  EXPECT_EQ(m.loads(), 1u);
  m.read_window(20, 30, 64, 64);
  EXPECT_EQ(m.loads(), 1u) << "second read of the same tile comes from the cache";
  m.read_window(2000, 2000, 64, 64);
  EXPECT_EQ(m.loads(), 2u);
  m.read_window(20, 30, 64, 64);
  EXPECT_EQ(m.loads(), 3u) << "a one-tile cache evicted the first tile";
}

// The window is read as a whole (its tiles decoded together) or tile by tile: tile_grid()
// of a mosaic with a one-tile cache copied by hand is the reference.
TEST(Mosaic, WindowOverFourTilesDecodedTogetherHoldsEachTilesOwnSamples) {
  test::TempDir dir;
  for (int s : {44, 45})
    for (int w : {-72, -71}) write_tile(dir.path(), s, w, 7.0f);  // edges differ: order shows
  const Mosaic together = Mosaic::open({dir.path()});
  const Mosaic one_by_one = Mosaic::open({dir.path()}, {}, 1);
  const int row0 = 1000, col0 = 1100, rows = 401, cols = 201;
  const Grid w = together.read_window(row0, col0, rows, cols);
  EXPECT_EQ(together.loads(), 4u);
  std::vector<char> done(static_cast<std::size_t>(rows) * cols, 0);
  for (std::size_t i = 0; i < one_by_one.tiles().size(); ++i) {
    const MosaicTile& t = one_by_one.tiles()[i];
    const Grid& g = *one_by_one.tile_grid(i);
    for (int r = std::max(row0, t.row0); r < std::min(row0 + rows, t.row0 + t.rows); ++r)
      for (int c = std::max(col0, t.col0); c < std::min(col0 + cols, t.col0 + t.cols); ++c) {
        const std::size_t o = static_cast<std::size_t>(r - row0) * cols + (c - col0);
        if (done[o]) continue;  // the first tile in input order gives a shared sample
        done[o] = 1;
        ASSERT_EQ(w.heights[o], g.heights[g.index(r - t.row0, c - t.col0)]) << "row " << r << " column " << c;
      }
  }
  EXPECT_EQ(std::count(done.begin(), done.end(), 1), static_cast<long>(rows) * cols);
  together.read_window(row0, col0, rows, cols);
  EXPECT_EQ(together.loads(), 4u) << "the second read comes from the cache";
}

TEST(Mosaic, ACachedWindowReadDecodesNothingAndGivesWhatTheReadGives) {
  test::TempDir dir;
  for (int s : {44, 45})
    for (int w : {-72, -71}) write_tile(dir.path(), s, w, 7.0f);
  const Mosaic m = Mosaic::open({dir.path()}, {}, 2);
  EXPECT_FALSE(m.read_cached_window(1100, 1150, 200, 100)) << "nothing is cached yet";
  EXPECT_EQ(m.loads(), 0u);
  m.read_window(10, 10, 64, 64);  // the north-west tile alone
  EXPECT_EQ(m.loads(), 1u);
  EXPECT_FALSE(m.read_cached_window(10, 1150, 64, 100)) << "the north-east tile is not cached";
  EXPECT_EQ(m.loads(), 1u);
  const std::optional<Grid> cached = m.read_cached_window(20, 30, 64, 64);
  ASSERT_TRUE(cached);
  const Grid read = m.read_window(20, 30, 64, 64);
  EXPECT_EQ(cached->heights, read.heights);
  EXPECT_EQ(cached->mask, read.mask);
  EXPECT_EQ(m.loads(), 1u);
}

// Two threads read seeded windows at once through a one-tile cache, so that each keeps
// evicting the tile the other is copying; each window must hold a serial read's samples.
TEST(Mosaic, WindowsReadOnTwoThreadsAtOnceHoldTheSerialReadsSamples) {
  test::TempDir dir;
  for (int s : {44, 45})
    for (int w : {-72, -71}) write_tile(dir.path(), s, w, 7.0f);
  const Mosaic shared = Mosaic::open({dir.path()}, {}, 1);
  const Mosaic serial = Mosaic::open({dir.path()}, {}, 4);
  struct Window {
    int row0, col0;
  };
  std::vector<Window> windows;
  std::mt19937 rng(20261207);
  std::uniform_int_distribution<int> at(0, 2400 - 40);
  for (int k = 0; k < 24; ++k) windows.push_back({at(rng), at(rng)});
  std::vector<Grid> got(windows.size());
  auto read = [&](std::size_t first) {
    for (std::size_t k = first; k < windows.size(); k += 2)
      got[k] = shared.read_window(windows[k].row0, windows[k].col0, 40, 40);
  };
  std::thread other(read, 1);
  read(0);
  other.join();
  for (std::size_t k = 0; k < windows.size(); ++k) {
    const Grid want = serial.read_window(windows[k].row0, windows[k].col0, 40, 40);
    EXPECT_EQ(got[k].heights, want.heights) << "window " << k;
    EXPECT_EQ(got[k].mask, want.mask) << "window " << k;
  }
}

TEST(Mosaic, WindowNeedingMoreTilesThanTheCacheReadsEachOnce) {
  test::TempDir dir;
  for (int s : {44, 45})
    for (int w : {-72, -71}) write_tile(dir.path(), s, w);
  const Mosaic m = Mosaic::open({dir.path()}, {}, 3);
  m.read_window(1100, 1150, 200, 100);
  EXPECT_EQ(m.loads(), 4u);
}

TEST(Mosaic, TwoBrokenTilesInOneWindowReportTheFirstInTileOrder) {
  test::TempDir dir;
  for (const char* name : {"40_41_111_112.sdf", "40_41_112_113.sdf"}) std::ofstream(dir.path() / name) << "not an SDF file\n";
  const Mosaic m = Mosaic::open({dir.path()});
  ASSERT_EQ(m.tiles().size(), 2u);
  for (int n = 0; n < 5; ++n) {  // the two fail in either order when decoded together
    try {
      m.read_window(0, 1190, 10, 20);
      FAIL() << "expected FormatError";
    } catch (const FormatError& e) {
      EXPECT_NE(std::string(e.what()).find(m.tiles()[0].path.filename().string()), std::string::npos) << e.what();
    }
  }
}

TEST(Mosaic, SharedEdgeSamplesComeFromTheFirstTileOnly) {
  test::TempDir dir;
  write_tile(dir.path(), 44, -72);
  write_tile(dir.path(), 44, -71, 7.0f);  // its west edge disagrees with its neighbour's east edge
  const Mosaic m = Mosaic::open({dir.path() / "N44W072.hgt", dir.path() / "N44W071.hgt"});
  const Grid w = m.read_window(0, 1199, 1, 3);
  EXPECT_EQ(w.heights[1], global_height(45.0, -71.0)) << "column 1200 is read from N44W072";
  EXPECT_EQ(m.cols(), 2401);
}

TEST(Mosaic, MissingTileIsAGapWithItsBounds) {
  test::TempDir dir;
  write_tile(dir.path(), 44, -72);
  write_tile(dir.path(), 45, -71);
  const Mosaic m = Mosaic::open({dir.path()});
  EXPECT_EQ(m.rows(), 2401);
  ASSERT_FALSE(m.gaps().empty());
  EXPECT_EQ(m.gap_samples(), 2u * 1200u * 1200u);
  const Grid w = m.read_window(0, 0, 10, 10);  // north-west: no tile
  EXPECT_EQ(count(w, Sample::kOutside), 100u);
  EXPECT_EQ(m.gaps().front().west, -72.0);
  EXPECT_EQ(m.gaps().front().north, 46.0);
}

TEST(Mosaic, WindowPastTheEdgeIsOutside) {
  test::TempDir dir;
  write_tile(dir.path(), 44, -72);
  const Mosaic m = Mosaic::open({dir.path()});
  const Grid w = m.read_window(-5, -5, 10, 10);
  EXPECT_EQ(count(w, Sample::kOutside), 100u - 25u);
  EXPECT_EQ(w.georef.x0, -72.0 - 5.0 / 1200.0);
}

TEST(Mosaic, DifferentSpacingsAreRejected) {
  const auto a = test::shared_dem("N44W072.hgt"), b = test::shared_dem("S46W066.hgt.gz");
  TERRAVOL_REQUIRE_SHARED(a);
  TERRAVOL_REQUIRE_SHARED(b);
  try {
    Mosaic::open({a, b});
    FAIL() << "expected FormatError";
  } catch (const FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("spacing"), std::string::npos) << e.what();
  }
}

TEST(Mosaic, EmptyDirectoryAndMissingPathAreErrors) {
  test::TempDir dir;
  EXPECT_THROW(Mosaic::open({dir.path()}), FormatError);
  EXPECT_THROW(Mosaic::open({dir.path() / "nope.hgt"}), FormatError);
}

TEST(Mosaic, TileOfTheWrongSizeIsReportedWithItsName) {
  test::TempDir dir;
  write_tile(dir.path(), 44, -72);
  std::ofstream(dir.path() / "N44W071.hgt", std::ios::binary) << "short";
  try {
    Mosaic::open({dir.path()});
    FAIL() << "expected FormatError";
  } catch (const FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("N44W071.hgt: size 5 bytes"), std::string::npos) << e.what();
  }
}

TEST(Mosaic, CompressedSrtmTilesArePlacedFromTheirNamesAndReadLikePlainOnes) {
  test::TempDir dir;
  write_tile(dir.path(), 44, -72, 0.0f, ".gz");
  write_tile(dir.path(), 44, -71, 0.0f, ".xz");
  write_tile(dir.path(), 45, -72, 0.0f, ".zip");
  write_tile(dir.path(), 45, -71, 0.0f, ".bz2");
  const Mosaic m = Mosaic::open({dir.path()});
  ASSERT_EQ(m.tiles().size(), 4u);
  EXPECT_EQ(m.rows(), 2401);
  EXPECT_EQ(m.cols(), 2401);
  EXPECT_TRUE(m.gaps().empty());
  EXPECT_EQ(m.loads(), 1u) << ".gz, .xz and .zip record their size; bzip2 does not, so that tile is read";
  const Grid w = m.read_window(1100, 1150, 200, 100);  // across all four tiles
  for (int r = 0; r < w.rows; ++r)
    for (int c = 0; c < w.cols; ++c) {
      ASSERT_EQ(w.mask[w.index(r, c)], Sample::kValid);
      ASSERT_EQ(w.heights[w.index(r, c)], global_height(46.0 - (1100 + r) / 1200.0, -72.0 + (1150 + c) / 1200.0));
    }
}

TEST(Mosaic, CompressedSdfTilesArePlacedFromTheirNamesWithoutBeingRead) {
  test::TempDir dir;
  write_sdf_tile(dir.path() / "40_41_111_112.sdf", 40, -112, ".gz");
  write_sdf_tile(dir.path() / "40:41:110:111.sdf", 40, -111, ".xz");
  const Mosaic m = Mosaic::open({dir.path()});
  ASSERT_EQ(m.tiles().size(), 2u);
  EXPECT_EQ(m.loads(), 0u);
  EXPECT_EQ(m.rows(), 1200);
  EXPECT_EQ(m.cols(), 2400);
  EXPECT_EQ(m.georef().x0, -112.0);
  const Grid w = m.read_window(0, 1190, 1200, 20);  // across the two tiles' meeting meridian
  EXPECT_EQ(m.loads(), 2u);
  for (int r = 0; r < w.rows; r += 7)
    for (int c = 0; c < w.cols; ++c) {
      ASSERT_EQ(w.mask[w.index(r, c)], Sample::kValid);
      ASSERT_EQ(w.heights[w.index(r, c)], global_height(41.0 - (r + 1) / 1200.0, -112.0 + (1190 + c) / 1200.0))
          << r << " " << c;
    }
}

TEST(Mosaic, UtahSdfDirectoryIsOneMosaicOfSixTiles) {
  const auto dir = test::shared_dem("utah_sdf");
  TERRAVOL_REQUIRE_SHARED(dir);
  const Mosaic m = Mosaic::open({dir});
  EXPECT_EQ(m.tiles().size(), 6u);
  EXPECT_EQ(m.rows(), 2400);
  EXPECT_EQ(m.cols(), 3600);
  EXPECT_TRUE(m.gaps().empty());
  EXPECT_NEAR(m.georef().x0, -113.0, 1e-9);
  EXPECT_EQ(m.loads(), 0u);
  const Grid w = m.read_window(1150, 1150, 100, 100);  // the corner where four tiles meet
  EXPECT_EQ(count(w, Sample::kValid), 10000u);
}

}  // namespace
}  // namespace terravol::io
