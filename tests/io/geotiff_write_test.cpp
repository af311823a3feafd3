#include "io/geotiff_write.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

#include "compress.h"
#include "geotiff_read.h"
#include "io/readers.h"
#include "temp_dir.h"

namespace terravol::io {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

GeoRaster random_raster(int rows, int cols, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> value(-150.0f, -40.0f);
  std::bernoulli_distribution hole(0.1);
  GeoRaster r;
  r.rows = rows;
  r.cols = cols;
  r.west = -112.25;
  r.north = 41.5;
  r.dlon = 3.0 / 3600.0;
  r.dlat = 2.0 / 3600.0;
  for (int i = 0; i < rows * cols; ++i) r.values.push_back(hole(rng) ? kNaN : value(rng));
  return r;
}

GeoTiffText text() { return {"path_loss_db at 10 m above ground", "dB"}; }

TEST(GeoTiffWrite, LibgeotiffReadsTheGeoreferenceAndEveryValueBack) {
  const GeoRaster r = random_raster(37, 50, 1);  // three strips, the last one short
  test::TempDir dir;
  const auto path = dir.path() / "map.tif";
  test::write_file_bytes(path, encode_geotiff(r, text()));
  const test::GeoTiffContents c = test::read_geotiff_file(path);
  ASSERT_TRUE(c.opened);
  EXPECT_EQ(c.width, 50u);
  EXPECT_EQ(c.height, 37u);
  EXPECT_EQ(c.bits, 32);
  EXPECT_EQ(c.sample_format, SAMPLEFORMAT_IEEEFP);
  EXPECT_EQ(c.samples_per_pixel, 1);
  EXPECT_EQ(c.tiepoint, (std::vector<double>{0, 0, 0, r.west, r.north, 0}));
  EXPECT_EQ(c.scale, (std::vector<double>{r.dlon, r.dlat, 0}));
  EXPECT_EQ(c.model_type, ModelTypeGeographic);
  EXPECT_EQ(c.raster_type, RasterPixelIsArea);
  EXPECT_EQ(c.geographic_type, 4326);
  EXPECT_EQ(c.angular_units, Angular_Degree);
  EXPECT_EQ(c.nodata, "nan");
  EXPECT_EQ(c.description, "path_loss_db at 10 m above ground");
  EXPECT_NE(c.gdal_metadata.find("<Item name=\"UNITTYPE\" sample=\"0\" role=\"unittype\">dB</Item>"), std::string::npos)
      << c.gdal_metadata;
  EXPECT_NE(c.gdal_metadata.find("role=\"description\">path_loss_db at 10 m above ground</Item>"), std::string::npos)
      << c.gdal_metadata;
  ASSERT_EQ(c.values.size(), r.values.size());
  for (std::size_t i = 0; i < r.values.size(); ++i) {
    if (std::isnan(r.values[i])) {
      ASSERT_TRUE(std::isnan(c.values[i])) << i;
    } else {
      ASSERT_EQ(c.values[i], r.values[i]) << i;
    }
  }
}

TEST(GeoTiffWrite, TerravolsReaderPlacesSamplesAtThePixelCentresWithNanAsVoid) {
  const GeoRaster r = random_raster(5, 7, 2);
  const std::vector<std::uint8_t> bytes = encode_geotiff(r);
  const Grid g = parse_geotiff(bytes, "map.tif");
  ASSERT_EQ(g.rows, 5);
  ASSERT_EQ(g.cols, 7);
  EXPECT_EQ(g.georef.crs, Crs::kGeographic);
  EXPECT_NEAR(g.georef.x0, r.centre_lon(0), 1e-12);
  EXPECT_NEAR(g.georef.y0, r.centre_lat(0), 1e-12);
  EXPECT_NEAR(g.georef.dx, r.dlon, 1e-15);
  EXPECT_NEAR(g.georef.dy, r.dlat, 1e-15);
  for (int row = 0; row < 5; ++row)
    for (int col = 0; col < 7; ++col) {
      const float v = r.at(row, col);
      if (std::isnan(v)) {
        EXPECT_EQ(g.mask[g.index(row, col)], Sample::kVoid);
      } else {
        EXPECT_EQ(g.heights[g.index(row, col)], v);
      }
    }
}

TEST(GeoTiffWrite, RefusesARasterWhoseValuesDoNotFitItsSize) {
  GeoRaster r = random_raster(3, 3, 3);
  r.values.pop_back();
  EXPECT_THROW(encode_geotiff(r), std::invalid_argument);
  r = random_raster(3, 3, 3);
  r.dlat = 0;
  EXPECT_THROW(encode_geotiff(r), std::invalid_argument);
  r.rows = 0;
  EXPECT_THROW(encode_geotiff(r), std::invalid_argument);
}

}  // namespace
}  // namespace terravol::io
