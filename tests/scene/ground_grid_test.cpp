// app/scene/ground_grid.h over the bundled DEM (N45E006, one SRTM3 tile): the reading
// constructor against the tile's own samples, and the cached variant, which decodes nothing.
#include "app/scene/ground_grid.h"

#include <gtest/gtest.h>

#include <optional>
#include <string>

#include "io/mosaic.h"

namespace terravol::app::scene {
namespace {

io::Mosaic bundled() {
  return io::Mosaic::open({std::string(TERRAVOL_SOURCE_DIR) + "/data/dem/N45E006.hgt"});
}

TEST(GroundGrid, AtALatticeSampleIsThatSampleAndBetweenSamplesBilinear) {
  const io::Mosaic m = bundled();
  const io::Grid tile = m.read_window(590, 290, 3, 3);  // rows 590.., columns 290..
  const auto h = [&](int r, int c) {
    return static_cast<double>(tile.heights[tile.index(r - 590, c - 290)]);
  };
  const GroundGrid g(m, 45.49, 45.51, 6.24, 6.26);
  // Row r lies at 46 - r / 1200 degrees N, column c at 6 + c / 1200 E (3" from 46 N, 6 E).
  const double lat = 46.0 - 591.0 / 1200.0, lon = 6.0 + 291.0 / 1200.0;
  EXPECT_NEAR(g(lat, lon), h(591, 291), 1e-6);
  EXPECT_NEAR(g(lat - 0.25 / 1200.0, lon + 0.5 / 1200.0),
              0.75 * (0.5 * h(591, 291) + 0.5 * h(591, 292)) +
                  0.25 * (0.5 * h(592, 291) + 0.5 * h(592, 292)),
              1e-9);
}

TEST(GroundGrid, FromTheCacheIsNothingUntilTheTileIsDecodedThenTheSameGround) {
  const io::Mosaic m = bundled();  // SRTM: placed from its name, not decoded yet
  EXPECT_FALSE(GroundGrid::cached(m, 45.49, 45.51, 6.24, 6.26));
  EXPECT_EQ(m.loads(), 0u) << "the cached variant decodes nothing";
  const GroundGrid read(m, 45.49, 45.51, 6.24, 6.26);
  EXPECT_EQ(m.loads(), 1u);
  const std::optional<GroundGrid> cached = GroundGrid::cached(m, 45.49, 45.51, 6.24, 6.26);
  ASSERT_TRUE(cached);
  EXPECT_EQ(m.loads(), 1u);
  for (const double dlat : {-0.007, 0.0, 0.0031})
    for (const double dlon : {-0.0052, 0.0, 0.009})
      EXPECT_EQ((*cached)(45.5 + dlat, 6.25 + dlon), read(45.5 + dlat, 6.25 + dlon));
}

}  // namespace
}  // namespace terravol::app::scene
